#include "cli/common.hpp"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <mutex>
#include <set>
#include <stdexcept>

#include "io/atomic_write.hpp"
#include "io/sha256.hpp"
#include "robot/robot_model.hpp"
#include "robot/robot_writer.hpp"
#include "tuning/observer_tuning.hpp"

namespace jg::cli {

void ObserverOptions::add_to(CLI::App* cmd) {
  cmd->add_option("--observer", preset, "Observer preset")
      ->check(CLI::IsMember({"first_order", "lowpass2", "paper_bandpass", "paper_improved"}))
      ->capture_default_str();
  cmd->add_option("--gains", gains,
                  "Observer gains K1[,K2[,K3]] [1/s] (first_order default: 150 at 500 Hz and above, 250 below)")
      ->delimiter(',');
  cmd->add_flag("--observer-torque-mean,!--no-observer-torque-mean", align_motor_torque,
                "Observer balance with the mean of the last two motor torques, centred like an encoder-difference "
                "momentum difference (off by default: right for the simulated drives, not for the UR10e's "
                "recordings); --no-observer-torque-mean: the torque of the sample (the default)");
}

ObserverGains ObserverOptions::to_gains(double rate_hz) const {
  if (gains.empty() && preset == "first_order") {
    ObserverGains d = tuning::default_gains(rate_hz);
    d.align_motor_torque = align_motor_torque;
    return d;
  }
  ObserverGains g;
  g.align_motor_torque = align_motor_torque;
  if (preset == "first_order") g.kind = ObserverKind::first_order;
  else if (preset == "lowpass2") g.kind = ObserverKind::lowpass2;
  else if (preset == "paper_bandpass") g.kind = ObserverKind::paper_bandpass;
  else g.kind = ObserverKind::paper_improved;
  const std::size_t needed = g.kind == ObserverKind::first_order ? 1 : (g.kind == ObserverKind::paper_improved ? 3 : 2);
  if (gains.size() < needed) {
    throw std::invalid_argument("--gains: the " + preset + " observer needs " + std::to_string(needed) +
                                " gains (K1[,K2[,K3]]), got " + std::to_string(gains.size()));
  }
  for (const double k : gains) {
    if (!(k > 0.0)) throw std::invalid_argument("--gains: every gain must be > 0 [1/s]");
  }
  g.k1 = gains[0];
  g.k2 = needed > 1 ? gains[1] : 0.0;
  g.k3 = needed > 2 ? gains[2] : 0.0;
  return g;
}

void add_model_selection(CLI::App* cmd, robot::LoadOptions& o) {
  cmd->add_option("--base", o.base_link, "URDF: first link of the chain (default: the root link)");
  cmd->add_option("--tip", o.tip_link, "URDF: last link of the chain (default: the deepest tip)");
  cmd->add_option("--drive", o.drive_file, "Drive parameters by joint name (YAML: joints, k_i, ...; docs/robot-model.md)")
      ->check(CLI::ExistingFile);
}

void check_scalar(const std::string& scalar) {
  if (scalar != "float" && scalar != "q") throw std::invalid_argument("--scalar must be float or q");
}

void RecordingOptions::add_to(CLI::App* cmd, const std::string& rate_help) {
  cmd->add_option("--torque-kind", torque_kind,
                  "What the torque columns are: auto (tau_j<j>, else tau_m<j>, else i<j>), current (i<j>), "
                  "motor (tau_m<j>), joint (a joint torque sensor: tau_j<j>, or tau_m<j> re-read as one; "
                  "no rotor inertia applied)")
      ->check(CLI::IsMember({"auto", "current", "motor", "joint"}))
      ->capture_default_str();
  cmd->add_option("--rate", rate_hz, rate_help)->check(CLI::Range(1.0, 100000.0));
  cmd->add_option("--max-gap", max_gap_s,
                  "Steps longer than this [s] split the recording into segments (default: 10 median steps and "
                  "at least 0.02 s); shorter gaps are interpolated over")
      ->check(CLI::PositiveNumber);
}

io::ReadOptions RecordingOptions::read_options() const {
  io::ReadOptions r;
  r.torque = io::parse_torque_choice(torque_kind);
  return r;
}

io::RegularizeOptions RecordingOptions::regularize_options() const {
  io::RegularizeOptions r;
  r.rate_hz = rate_hz;
  r.max_gap_s = max_gap_s;
  return r;
}

std::string torque_description(io::TorqueKind kind) {
  switch (kind) {
    case io::TorqueKind::current: return "i (motor current x K_I; rotor inertia applied)";
    case io::TorqueKind::tau_m: return "tau_m (motor torque; rotor inertia applied)";
    case io::TorqueKind::tau_j: return "tau_j (joint torque sensor; no rotor inertia)";
  }
  return "?";
}

LoadedRecording load_recording(const std::string& path, const RecordingOptions& o) {
  // The side file jointguard wrote beside it: which command and version made the recording.
  if (io::classify_side_file(io::side_file_path(path)) == io::SideFile::ours) {
    report_input_identity("recording side file", io::side_file_path(path));
  }
  LoadedRecording out = workflow::load_recording(path, o.read_options(), o.regularize_options());
  std::printf("%s\n", out.data.report.summary().c_str());
  std::printf("torque: %s\n", torque_description(out.torque).c_str());
  return out;
}

CLI::Validator output_file(bool creates_folders) {
  return CLI::Validator(
      [creates_folders](std::string& path) {
        namespace fs = std::filesystem;
        std::error_code ec;
        if (path.empty()) return std::string("an empty path");
        if (fs::is_directory(path, ec)) return "'" + path + "' is a folder, not a file";
        fs::path folder = fs::path(path).has_parent_path() ? fs::path(path).parent_path() : fs::path(".");
        if (creates_folders) {
          // The writer creates the missing folders: the nearest existing one must be a
          // writable folder (not a file in the way).
          while (!fs::exists(folder, ec) && folder.has_parent_path() && folder.parent_path() != folder) folder = folder.parent_path();
        }
        if (!fs::is_directory(folder, ec)) {
          return fs::exists(folder, ec) ? "'" + folder.string() + "' in '" + path + "' is a file, not a folder"
                                        : "the folder '" + folder.string() + "' of '" + path + "' does not exist";
        }
        if (::access(folder.c_str(), W_OK) != 0) return "the folder '" + folder.string() + "' of '" + path + "' is not writable";
        return std::string();
      },
      creates_folders ? "FILE (missing folders are created)" : "FILE (in an existing folder)");
}

CLI::Validator recording_output_file() {
  const CLI::Validator folder = output_file(true);
  return CLI::Validator(
      [folder](std::string& path) {
        std::string ext = std::filesystem::path(path).extension().string();
        for (auto& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
        if (ext == ".json") {
          return "'" + path + "' ends in .json: a recording is a CSV file (e.g. '" +
                 std::filesystem::path(path).replace_extension(".csv").string() + "'); its metadata goes to <name>.json beside it";
        }
        std::string p = path;
        return folder(p);
      },
      "FILE.csv (missing folders are created; <name>.json beside it)");
}

CLI::Validator finite_range(double lo, double hi) {
  return CLI::Validator(
      [lo, hi](std::string& text) {
        char* end = nullptr;
        const double v = std::strtod(text.c_str(), &end);
        if (end == text.c_str() || *end != '\0' || !std::isfinite(v) || v < lo || v > hi) {
          return "'" + text + "' is not a finite number in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
        }
        return std::string();
      },
      "FINITE in [" + std::to_string(lo) + " - " + std::to_string(hi) + "]");
}

std::string file_sha256(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::invalid_argument(path + ": cannot open");
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return io::sha256_hex(bytes);
}

nlohmann::json command_identity(const CLI::App& cmd, const std::vector<std::string>& skip) {
  nlohmann::json id{{"version", JG_VERSION}, {"command", cmd.get_name()}};
  nlohmann::json options = nlohmann::json::object(), files = nlohmann::json::object();
  for (const CLI::Option* opt : cmd.get_options()) {
    const std::string name = opt->get_name();
    if (opt->count() == 0 || std::find(skip.begin(), skip.end(), name) != skip.end() || name == "--help" ||
        name == "--help-all") {
      continue;
    }
    options[name] = opt->results();
    for (const auto& v : opt->results()) {
      std::error_code ec;
      if (!std::filesystem::is_regular_file(v, ec)) continue;
      files[v] = file_sha256(v);
    }
  }
  id["options"] = options;
  id["input_sha256"] = files;
  return id;
}

namespace {
const CLI::App* g_running = nullptr;

/// One console line for a robot file a jointguard command wrote (its `identity` key), as
/// report_input_identity says it for JSON; once per file and run (a command may load its model
/// in several steps or threads). Hand-written robot files (no key) pass in silence: they are
/// the common case and their path is on the command line.
void report_robot_identity(const robot::RobotModel& m) {
  if (m.written_by_version.empty()) return;
  static std::mutex mutex;
  static std::set<std::string> reported;
  const std::lock_guard<std::mutex> lock(mutex);
  if (!reported.insert(m.source).second) return;
  std::ifstream in(m.source, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::printf("robot file: %s (jointguard %s %s, sha256 %s)\n", m.source.c_str(), m.written_by_version.c_str(),
              m.written_by_command.c_str(), io::sha256_hex(bytes).substr(0, 12).c_str());
  if (m.written_by_version != JG_VERSION) {
    std::fflush(stdout);
    std::fprintf(stderr, "warning: robot file %s was written by jointguard %s, this is %s: its figures may differ from what this version writes\n",
                 m.source.c_str(), m.written_by_version.c_str(), JG_VERSION);
  }
}
}  // namespace

void set_running_command(const CLI::App& cmd) {
  g_running = &cmd;
  // Robot files written by this command carry its identity; those it reads say theirs.
  robot::set_identity_source([] { return result_identity(); });
  robot::set_read_observer(report_robot_identity);
}

nlohmann::json result_identity() {
  if (g_running == nullptr) return nlohmann::json::object();
  return command_identity(*g_running, {"--json", "--out", "--model-out", "--trace", "--jobs", "--shard"});
}

void report_input_identity(const std::string& what, const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return;
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const nlohmann::json j = nlohmann::json::parse(bytes, nullptr, false);
  if (j.is_discarded() || !j.is_object()) return;
  const nlohmann::json* id = nullptr;
  if (j.contains("identity") && j["identity"].is_object()) {
    id = &j["identity"];
  } else if (j.contains("jointguard_partial") && j["jointguard_partial"].is_object() &&
             j["jointguard_partial"].contains("identity") && j["jointguard_partial"]["identity"].is_object()) {
    id = &j["jointguard_partial"]["identity"];
  }
  const auto text = [](const nlohmann::json& o, const char* key) {
    return o.contains(key) && o[key].is_string() ? o[key].get<std::string>() : std::string("?");
  };
  const std::string sha = io::sha256_hex(bytes).substr(0, 12);
  if (id == nullptr) {
    std::printf("%s: %s (no identity: written by hand, by another tool or by a jointguard before %s; sha256 %s)\n", what.c_str(), path.c_str(),
                JG_VERSION, sha.c_str());
    return;
  }
  const std::string version = text(*id, "version");
  std::printf("%s: %s (jointguard %s %s, sha256 %s)\n", what.c_str(), path.c_str(), version.c_str(), text(*id, "command").c_str(),
              sha.c_str());
  if (version != JG_VERSION) {
    std::fflush(stdout);
    std::fprintf(stderr, "warning: %s %s was written by jointguard %s, this is %s: its figures may differ from what this version writes\n",
                 what.c_str(), path.c_str(), version.c_str(), JG_VERSION);
  }
}

void write_json_file(const std::string& path, const nlohmann::json& j) {
  if (j.is_object() && !j.contains("identity") && g_running != nullptr) {
    nlohmann::json with = j;
    with["identity"] = result_identity();
    io::write_json_atomic(path, with);
    return;
  }
  io::write_json_atomic(path, j);
}

}  // namespace jg::cli
