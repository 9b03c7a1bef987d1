// Writes the golden input: the reference arm (models/ref3.yaml) converted to firmware
// constants, the paper's LuGre (Table 1) and the first-order observer discretised at
// 1 kHz, and 5 s of a simulated pick-and-collide run (q, dq, tau_m as float32).
// Usage: jg_golden_make_input <ref3.yaml> <output>
#include <cstdio>
#include <fstream>
#include <vector>

#include "golden.hpp"
#include "golden_io.hpp"
#include "models/paper_friction.hpp"
#include "robot/robot_model.hpp"
#include "sim/simulation.hpp"

namespace {
template <class S>
void write_setup(jg::golden::Cursor& c, const jg::robot::RobotModel& m, double dt) {
  auto wr = [&c](auto& v) { jg::golden::put(c, v); };
  for (int j = 0; j < 3; ++j) {
    jg::LuGreDiscrete<S> d{};
    if (jg::discretize(jg::sim::kPaperTable1[static_cast<std::size_t>(j)], dt, d) != jg::Error::ok) throw std::runtime_error("lugre");
    jg::golden::visit(d, wr);
  }
  for (int j = 0; j < 3; ++j) {
    jg::ObserverCoeffs<S> o{};
    if (jg::discretize(jg::ObserverGains{jg::ObserverKind::first_order, 60.0, 0.0, 0.0}, dt, o) != jg::Error::ok) throw std::runtime_error("observer");
    c.put32(o.sections);
    jg::golden::visit(o, wr);
  }
  for (int j = 0; j < 3; ++j) {
    jg::LinkConstants<S> l{};
    if (jg::convert_link(m.joints[static_cast<std::size_t>(j)].link, l) != jg::Error::ok) throw std::runtime_error("link");
    jg::golden::visit(l, wr);
  }
}
}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s <ref3.yaml> <output>\n", argv[0]);
    return 2;
  }
  const auto model = jg::robot::load_robot(argv[1]);
  jg::sim::SimulationSetup s;
  s.plant.links = model.plant_links();
  for (const auto& p : jg::sim::kPaperTable1) s.plant.friction.push_back({p, {}});
  s.sensors.drives = model.drives();
  for (auto& d : s.sensors.drives) d.current_noise_rms_a = 0.01;
  s.controller.kp = {1600.0, 1600.0, 800.0};
  s.controller.kd = {80.0, 80.0, 40.0};
  jg::sim::JointVector home(3), work(3);
  home << 0.0, 0.6, -0.8;
  work << 0.8, 1.0, -1.2;
  s.trajectory = jg::sim::make_pick_task(home, work, 1);
  jg::sim::CollisionEvent e;
  e.t_start = 2.5;
  e.link = 3;
  e.point_in_link = {0.2, 0.0, 0.0};
  e.direction_base = {0.0, 0.0, 1.0};
  e.profile = jg::sim::CollisionProfile::push;
  e.peak_force_n = 80.0;
  e.duration_s = 0.5;
  s.collisions = {e};
  s.duration_s = 4.999;
  const auto rec = jg::sim::run_simulation(s).recording;
  std::vector<std::uint8_t> buf(600 * 1024);
  jg::golden::Cursor c{buf.data(), buf.size()};
  c.put32(jg::golden::kMagic);
  c.put32(static_cast<std::uint32_t>(rec.samples()));
  write_setup<float>(c, model, 0.001);
  write_setup<jg::q16>(c, model, 0.001);
  for (std::size_t k = 0; k < rec.samples(); ++k) {
    for (const auto* sig : {&rec.q, &rec.dq, &rec.tau_m}) {
      for (std::size_t j = 0; j < 3; ++j) jg::golden::put(c, static_cast<float>((*sig)[j][k]));
    }
  }
  if (!c.ok) return 3;
  std::ofstream(argv[2], std::ios::binary).write(reinterpret_cast<const char*>(buf.data()), static_cast<std::streamsize>(c.pos));
  std::printf("golden input: %zu samples, %zu bytes\n", rec.samples(), c.pos);
  return 0;
}
