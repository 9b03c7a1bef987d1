#include "hil/hil_run.hpp"

#include <cstdio>
#include <fstream>
#include <stdexcept>

#include "detection/contact_estimate.hpp"
#include "eval/distributed_estimator.hpp"
#include "hil/socketcan_master.hpp"
#include "io/atomic_write.hpp"
#include "io/trace_csv.hpp"

namespace jg::hil {

HilResult run_hil(const sim::Scenario& scenario, const HilConfig& c) {
  const sim::SimulationSetup& setup = scenario.setup;
  const std::size_t n = setup.plant.links.size();
  if (c.model.joints.size() != n) {
    throw std::invalid_argument("the robot file has " + std::to_string(c.model.joints.size()) + " joints, the scenario's plant " +
                                std::to_string(n));
  }
  if (c.thresholds.threshold.size() != n) throw std::invalid_argument("the threshold file needs one threshold per joint");
  if (!c.friction.empty() && c.friction.size() != n) throw std::invalid_argument("the friction file needs one LuGre set per joint");
  eval::DetectionConfig d;
  d.threshold = c.thresholds.threshold;
  d.low_speed_extra = c.thresholds.low_speed_extra;
  d.low_speed_width = c.thresholds.low_speed_width;
  d.debounce_cycles = c.debounce_cycles;
  d.hold_threshold = c.thresholds.hold_change;
  d.hold_settle_s = c.thresholds.hold_settle_s;
  d.hold_reference_s = c.thresholds.hold_reference_s;
  d.reaction = c.reaction;
  d.friction = c.friction;
  // The master's contact estimate from the drives' torques (as in evaluate).
  d.contact.observer_gain_per_s = c.gains.kind == ObserverKind::first_order ? c.gains.k1 : 0.0;
  d.contact.estimator = detection::default_contact_params(c.model.reaches(), c.model.reach_axes());
  HilResult out;
  const std::string name = setup.meta.scenario.empty() ? scenario.file : setup.meta.scenario;
  if (c.interface.empty()) {
    eval::DistributedConfig dc;
    dc.estimator.model = c.model;
    dc.estimator.dt = 1.0 / setup.control_rate_hz;
    dc.estimator.observer = c.gains;
    dc.estimator.compensate_friction = !c.friction.empty();
    dc.estimator.friction = c.friction;
    dc.node_thresholds = eval::threshold_bands(c.thresholds);
    if (!c.thresholds.hold_change.empty()) {
      // The threshold file carries a holding detector: the drives run it on the holding
      // flag of their sensor frames, with the estimate's velocity deadband.
      dc.estimator.holding_velocity_deadband = eval::holding_deadband(c.model, setup.control_rate_hz);
      for (const double h : c.thresholds.hold_change) {
        dc.node_hold.push_back(eval::hold_params(h, c.thresholds.hold_settle_s, c.thresholds.hold_reference_s, dc.estimator.dt));
      }
    }
    dc.debounce_cycles = c.debounce_cycles;
    dc.fault_specs = c.faults;
    auto est = eval::make_distributed_estimator(dc, c.scalar);
    out.run = eval::run_detection(setup, *est, d, name, true);
    const eval::BusStatistics s = est->statistics();
    out.events = s.events;
    out.master = s.master;
    out.bus_frames = s.frames;
    out.bus_busy_s = s.busy_s;
    out.bus_elapsed_s = s.elapsed_s;
    out.incomplete_cycles = s.incomplete_cycles;
    out.drives = s.drives;
    out.first_comm_fault_cycle = s.first_comm_fault_cycle;
    out.fault_episodes = s.fault_episodes;
    out.master_comm_fault_end = est->communication_fault();
    out.master_input_fault_end = est->input_fault();
    char bus[64];
    std::snprintf(bus, sizeof bus, "simulated CAN FD %g/%g Mbit/s", dc.timing.nominal_bps / 1e6, dc.timing.data_bps / 1e6);
    out.bus = bus;
  } else {
    SocketCanMasterConfig mc;
    mc.interface = c.interface;
    mc.joints = n;
    mc.cycle_timeout_ms = c.cycle_timeout_ms;
    mc.period_s = 1.0 / setup.control_rate_hz;
    check_socketcan_faults(c.faults);
    mc.faults = c.faults;
    auto est = make_socketcan_master(mc);
    out.run = eval::run_detection(setup, *est, d, name, true);
    out.master_comm_fault_end = est->communication_fault();
    out.master_input_fault_end = est->input_fault();
    out.events = est->events();
    out.master = est->counters();
    out.first_comm_fault_cycle = est->first_comm_fault_cycle();
    out.fault_episodes = est->fault_episodes();
    out.bus = "SocketCAN " + c.interface;
  }
  return out;
}

void write_trace_csv(const std::string& path, const eval::Trace& trace) {
  // every write checked, nothing partial left behind
  io::write_text_atomic(path, io::trace_csv(trace.t, trace.mu, io::joint_ids_1_to(trace.mu.size())));
}

}  // namespace jg::hil
