// `jointguard decode`: decodes a candump capture of the joint bus with the DBC and reports
// the traffic per cycle (what the simulated bus model predicts, checked on real traffic).
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>

#include "can/dbc.hpp"
#include "can/sim_bus.hpp"
#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "io/atomic_write.hpp"
#include "jointguard/protocol/frames.hpp"

namespace jg::cli {
namespace {
struct DecodeOptions {
  std::string capture, dbc = JG_DEFAULT_DBC, json;
  double nominal_bps = 1e6, data_bps = 5e6;
};

/// What the capture's decodable frames add up to.
struct Traffic {
  std::map<std::string, std::size_t> count;
  std::vector<std::string> problems;  // the first ten, for the message
  std::size_t undecodable = 0;
  std::size_t cycles = 0, product_frames = 0, announcements = 0;
  double product_s = 0.0, all_s = 0.0;
  nlohmann::json events = nlohmann::json::array(), last = nlohmann::json::object();
};

/// Why a frame is not a DBC message of the right length and format (empty: it is).
std::string frame_problem(const can::Dbc& dbc, const hal::CanFrame& f) {
  const auto it = dbc.messages.find(f.id);
  if (f.extended) {
    char id[16];
    std::snprintf(id, sizeof id, "0x%08X", f.id);
    return std::string("identifier ") + id + " is extended (29 bits); the joint protocol's are 11 bits";
  } else if (it == dbc.messages.end()) {
    char id[16];
    std::snprintf(id, sizeof id, "0x%03X", f.id);
    return std::string("identifier ") + id + " is not in the DBC";
  } else if (it->second.length != f.length) {
    return it->second.name + ": " + std::to_string(f.length) + " bytes, the DBC says " + std::to_string(it->second.length);
  } else if (it->second.fd != f.fd) {
    return it->second.name + (f.fd ? ": CAN FD frame, the DBC says classic" : ": classic frame, the DBC says CAN FD");
  }
  return {};
}

/// A decodable frame (message m, captured at time) into the traffic: its count and wire
/// time, the product traffic per cycle (start-up announcements and host-in-the-loop sensor
/// frames left out), collision events, each message's last signals.
void count_frame(const can::DbcMessage& m, const hal::CanFrame& f, double time, const can::BusTiming& timing, Traffic& t) {
  ++t.count[m.name];
  const double wire = can::frame_duration_s(f, timing);
  t.all_s += wire;
  if (f.id == protocol::kSyncId) ++t.cycles;
  const bool announcement = protocol::kind_of(f.id) == protocol::MessageKind::status && f.length > 5 &&
                            (f.data[5] & protocol::kStatusBooting) != 0U;
  if (announcement) {
    ++t.announcements;  // start-up only, not per-cycle traffic
  } else if (protocol::kind_of(f.id) == protocol::MessageKind::joint_state && protocol::joint_of(f.id) != 0U) {
    // A reacting drive's status with its reaction torque: on the arm the drive
    // sends its 8-byte status (the torque goes to its own motor), so that is what
    // the product traffic counts.
    hal::CanFrame as_status = f;
    as_status.length = protocol::kStatusFrameLength;
    ++t.product_frames;
    t.product_s += can::frame_duration_s(as_status, timing);
  } else if (protocol::kind_of(f.id) != protocol::MessageKind::sensor) {
    ++t.product_frames;
    t.product_s += wire;
  }
  nlohmann::json sig;
  for (const auto& s : m.signals) sig[s.name] = can::decode_signal(s, f.data, f.length);
  if (protocol::kind_of(f.id) == protocol::MessageKind::collision_event) {
    t.events.push_back({{"t", time}, {"message", m.name}, {"signals", sig}});
  }
  t.last[m.name] = sig;
}

/// The traffic printed and (--json, when every frame decoded) written; exit 1 for a frame
/// not decodable.
int report_traffic(const DecodeOptions& o, std::size_t n_frames, const Traffic& t) {
  const double per_cycle_us = t.cycles ? 1e6 * t.product_s / static_cast<double>(t.cycles) : 0.0;
  std::printf("%zu frames, %zu cycles (CYCLE_SYNC), %zu start-up announcements; %zu frames not decodable\n", n_frames,
              t.cycles, t.announcements, t.undecodable);
  for (const auto& p : t.problems) std::printf("  %s\n", p.c_str());
  for (const auto& [name, n] : t.count) std::printf("  %-20s %8zu\n", name.c_str(), n);
  if (t.cycles) {
    std::printf("per cycle without the host-in-the-loop sensor frames: %.2f frames, %.1f us of wire time at %.0f/%.0f kbit/s "
                "(highest rate %.0f Hz at 100 %% load)\n",
                static_cast<double>(t.product_frames) / static_cast<double>(t.cycles), per_cycle_us, o.nominal_bps / 1e3,
                o.data_bps / 1e3, 1e6 / per_cycle_us);
  }
  if (!o.json.empty()) {
    nlohmann::json j{{"frames", n_frames}, {"cycles", t.cycles}, {"announcements", t.announcements}, {"undecodable", t.undecodable}, {"problems", t.problems},
                     {"messages", t.count}, {"events", t.events}, {"last", t.last},
                     {"product_frames_per_cycle", t.cycles ? static_cast<double>(t.product_frames) / static_cast<double>(t.cycles) : 0.0},
                     {"product_wire_us_per_cycle", per_cycle_us},
                     {"all_wire_us_per_cycle", t.cycles ? 1e6 * t.all_s / static_cast<double>(t.cycles) : 0.0},
                     {"nominal_bps", o.nominal_bps}, {"data_bps", o.data_bps}};
    // Bad input writes nothing (README): the problems are printed above, exit 1.
    if (t.undecodable == 0) {
      write_json_file(o.json, j);  // with the identity
    } else {
      std::fprintf(stderr, "jointguard decode: %s: %zu frames not decodable: %s not written\n", o.capture.c_str(), t.undecodable,
                   o.json.c_str());
    }
  }
  return t.undecodable == 0 ? 0 : 1;
}
}  // namespace

Command add_decode(CLI::App& app) {
  auto o = std::make_shared<DecodeOptions>();
  auto* cmd = app.add_subcommand("decode",
                                 "Decode a capture of the joint bus (candump -L) with the DBC: every frame must be a known\n"
                                 "message of the right length and format; reports frames and wire time per cycle.\n"
                                 "Example: candump -L vcan0 > capture.log; jointguard decode capture.log --json out/traffic.json");
  cmd->add_option("capture", o->capture, "candump -L log")->required()->check(CLI::ExistingFile);
  cmd->add_option("--dbc", o->dbc, "Bus description")->capture_default_str()->check(CLI::ExistingFile);
  cmd->add_option("--nominal", o->nominal_bps, "Arbitration bit rate for the wire-time figures [bit/s]")->capture_default_str()
      ->check(CLI::Range(1e4, 1e7));
  cmd->add_option("--data", o->data_bps, "CAN FD data-phase bit rate [bit/s]")->capture_default_str()->check(CLI::Range(1e4, 1.6e7));
  cmd->add_option("--json", o->json, "Write the decoded traffic here")->check(output_file());
  return {cmd, [o]() {
            const can::Dbc dbc = can::read_dbc(o->dbc);
            const auto frames = can::read_candump_log(o->capture);
            Traffic t;
            const can::BusTiming timing{o->nominal_bps, o->data_bps};
            for (std::size_t i = 0; i < frames.size(); ++i) {
              const hal::CanFrame& f = frames[i].frame;
              const std::string problem = frame_problem(dbc, f);
              if (!problem.empty()) {
                if (++t.undecodable <= 10) t.problems.push_back("frame " + std::to_string(i + 1) + ": " + problem);
                continue;
              }
              count_frame(dbc.messages.find(f.id)->second, f, frames[i].t, timing, t);
            }
            return report_traffic(*o, frames.size(), t);
          }};
}

}  // namespace jg::cli
