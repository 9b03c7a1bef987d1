// The reader of `jointguard merge`: the parts that `evaluate --shard K/N` writes
// (partial_json), read back and checked against one another (one campaign, every shard once,
// nothing missing or twice). Apart from the CLI so the fuzz target (tests/fuzz/fuzz_merge_parts.cpp)
// links it without the evaluation code.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <optional>
#include <set>
#include <stdexcept>

#include "cli/evaluate_output.hpp"
#include "eval/contact_coverage.hpp"

namespace jg::cli {
namespace {
constexpr int kMaxShards = 100000;        ///< as parse_shard allows
constexpr int kMaxPartItems = 100000000;  ///< runs or free-run segments of one campaign

/// A whole number in [lo, hi] from a part's field, refused naming the field otherwise (a
/// count of 2e9 would otherwise be taken as far as the memory goes).
int bounded_int(const nlohmann::json& v, const std::string& field, int lo, int hi) {
  if (!v.is_number_integer() && !(v.is_number_float() && std::floor(v.get<double>()) == v.get<double>())) {
    throw std::invalid_argument("field '" + field + "': not a whole number");
  }
  const double x = v.get<double>();
  if (!(x >= lo && x <= hi)) {
    throw std::invalid_argument("field '" + field + "': " + v.dump() + " outside " + std::to_string(lo) + ".." + std::to_string(hi));
  }
  return static_cast<int>(x);
}

/// A whole number read as an int: within [-1e6, 1e6] (links, joints, counts of a few). nlohmann's
/// get<int>() casts a double such as 1e300 unchecked: undefined behaviour (fuzz_merge_parts).
constexpr int kMaxSmallInt = 1000000;
int small_int(const nlohmann::json& j, const char* key) { return bounded_int(j.at(key), key, -kMaxSmallInt, kMaxSmallInt); }

Eigen::Vector3d vector_of(const nlohmann::json& j) { return {j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>()}; }

eval::ContactOutcome contact_from_json(const nlohmann::json& j) {
  eval::ContactOutcome c;
  c.t = j.at("t").get<double>();
  c.estimate.link = small_int(j, "link");
  c.estimate.link_chi2 = j.at("link_residual_chi2").get<std::vector<double>>();
  c.estimate.along_m = j.at("along_link").get<double>();
  c.estimate.along_sigma_m = j.at("along_link_sigma").get<double>();
  c.estimate.point_in_link = vector_of(j.at("point_in_link"));
  c.estimate.point_base = vector_of(j.at("point_base"));
  c.estimate.force_n = j.at("force").get<double>();
  c.estimate.force_sigma_n = j.at("force_sigma").get<double>();
  c.estimate.force_base = vector_of(j.at("force_base"));
  c.estimate.determined_components = small_int(j, "determined_force_components");
  c.estimate.residual_chi2 = j.at("residual_chi2").get<double>();
  const auto tau = j.at("torque").get<std::vector<double>>();
  const auto sigma = j.at("torque_sigma").get<std::vector<double>>();
  c.observation.tau_nm = Eigen::Map<const Eigen::VectorXd>(tau.data(), static_cast<Eigen::Index>(tau.size()));
  c.observation.sigma_nm = Eigen::Map<const Eigen::VectorXd>(sigma.data(), static_cast<Eigen::Index>(sigma.size()));
  c.force_true_n = j.at("force_true_at_estimate").get<double>();
  c.along_true_m = j.at("along_link_true").get<double>();
  c.point_error_m = j.at("point_error").is_null() ? -1.0 : j.at("point_error").get<double>();
  c.force_at_true_point_n = j.at("force_given_true_point").get<double>();
  c.peak_force_n = j.at("peak_force").get<double>();
  c.t_peak = j.at("t_peak_force").get<double>();
  c.torque_true_nm = j.at("torque_true").get<std::vector<double>>();
  c.force_true_observed_n = j.value("force_true_observed", 0.0);
  c.t_force = j.value("t_force", c.t);
  c.force_given_true_link_n = j.value("force_given_true_link", 0.0);
  c.along_given_true_link_m = j.value("along_link_given_true_link", 0.0);
  if (j.contains("point_error_given_true_link") && !j.at("point_error_given_true_link").is_null()) {
    c.point_error_given_true_link_m = j.at("point_error_given_true_link").get<double>();
  }
  if (j.contains("point_true")) c.point_true = vector_of(j.at("point_true"));
  if (j.contains("links_consistent")) {
    for (const auto& l : j.at("links_consistent")) bounded_int(l, "links_consistent[]", -kMaxSmallInt, kMaxSmallInt);
  }
  eval::contact_set_from_json(j, c);
  return c;
}

std::optional<double> optional_of(const nlohmann::json& j, const char* key) {
  const auto& v = j.at(key);
  if (v.is_null()) return std::nullopt;
  return v.get<double>();
}

eval::RunResult run_from_json(const nlohmann::json& j) {
  eval::RunResult r;
  r.name = j.at("name").get<std::string>();
  r.index = j.at("index").get<int>();
  r.t_collision = j.at("t_collision").get<double>();
  r.t_detected = optional_of(j, "t_detected");
  r.t_threshold = optional_of(j, "t_threshold_crossed");
  r.link_true = small_int(j, "link_true");
  r.link_isolated = small_int(j, "link_isolated");
  r.peak_force_n = j.at("peak_force").get<double>();
  r.max_true_ratio = j.at("max_true_torque_over_threshold").get<double>();
  r.max_true_ratio_moving = j.at("max_true_torque_over_moving_threshold").get<double>();
  r.isolable = j.at("isolable").get<bool>();
  r.isolable_at_decision = j.value("isolable_at_decision", false);
  r.link_first_cycle = small_int(j, "link_first_cycle");
  r.detected_by_hold = j.at("detected_by_hold").get<bool>();
  r.peak_true_torque_held = j.at("peak_true_torque_held").get<double>();
  r.held_push_nm = j.at("held_push").get<double>();
  r.peak_true_torque_own = j.value("peak_true_torque_own", 0.0);
  r.peak_reaching_torque_own = j.value("peak_reaching_torque_own", r.peak_true_torque_own);
  r.peak_joint = j.contains("peak_joint") ? small_int(j, "peak_joint") : 0;
  r.detected_by_residual = j.value("detected_by_residual", false);
  r.peak_true_torque_nm = j.value("peak_true_torque", 0.0);
  r.speed_at_peak_rad_s = j.value("speed_at_peak", 0.0);
  r.compared = j.contains("t_detected_other_scalar");
  if (r.compared) r.t_detected_other = optional_of(j, "t_detected_other_scalar");
  if (j.contains("bus")) {
    const auto& b = j.at("bus");
    r.bus = eval::RunResult::BusLoad{b.at("frames").get<std::size_t>(), b.at("incomplete_cycles").get<std::size_t>(),
                                     b.at("busy_s").get<double>(), b.at("elapsed_s").get<double>()};
  }
  if (j.contains("contact_estimate") && !j.at("contact_estimate").is_null()) r.contact = contact_from_json(j.at("contact_estimate"));
  return r;
}

/// The first field in which two identities differ, said for a user ("option --seed: 3 here,
/// 4 there").
std::string identity_difference(const nlohmann::json& here, const nlohmann::json& there) {
  const nlohmann::json patch = nlohmann::json::diff(there, here);
  if (patch.empty()) return "identity differs";
  const std::string path = patch.front().value("path", std::string());
  const nlohmann::json::json_pointer ptr(path);
  const std::string a = here.contains(ptr) ? here.at(ptr).dump() : "absent";
  const std::string b = there.contains(ptr) ? there.at(ptr).dump() : "absent";
  return "identity" + path + " is " + a + " here, " + b + " there";
}
/// What the parts read so far agree on: the first part's head (and its file), the shards,
/// runs and free-run segments seen.
struct MergeState {
  nlohmann::json first_head;
  std::string first_path;
  std::set<int> shards_seen, run_indices, segment_indices;
  int shards = 0;
  std::size_t runs_total = 0, segments_total = 0;
};

/// One part (file path) into out: its head checked against the first part's, its extra
/// fields, runs and free-run segments (each index once over all parts).
void merge_part(const nlohmann::json& p, const std::string& path, MergeState& m, EvaluateFigures& out) {
  const auto& head = p.at("jointguard_partial");
  const int shard = bounded_int(head.at("shard"), "shard", 1, kMaxShards);
  const int n = bounded_int(head.at("shards"), "shards", 1, kMaxShards);
  if (m.first_path.empty()) {
    m.first_head = head;
    m.first_path = path;
    m.shards = n;
    m.runs_total = static_cast<std::size_t>(bounded_int(head.at("runs_total"), "runs_total", 0, kMaxPartItems));
    m.segments_total = static_cast<std::size_t>(bounded_int(head.at("segments_total"), "segments_total", 0, kMaxPartItems));
    out.config = head.at("config");
    if (head.contains("identity")) out.identity = head.at("identity");
    out.free_run_s = head.at("free_run_s").get<double>();
  } else {
    for (const char* key : {"shards", "runs_total", "segments_total", "free_run_s", "identity", "config"}) {
      if (head.at(key) != m.first_head.at(key)) {
        if (std::string(key) == "identity") {
          throw std::invalid_argument("made otherwise than " + m.first_path + ": " +
                                      identity_difference(head.at(key), m.first_head.at(key)) +
                                      ": the parts are not of one campaign (same command, other --shard)");
        }
        throw std::invalid_argument("field '" + std::string(key) + "' differs from " + m.first_path +
                                    "'s: the parts are not of one campaign (same command, other --shard)");
      }
    }
  }
  if (shard < 1 || shard > n) throw std::invalid_argument("shard " + std::to_string(shard) + " outside 1.." + std::to_string(n));
  if (!m.shards_seen.insert(shard).second) {
    throw std::invalid_argument("shard " + std::to_string(shard) + "/" + std::to_string(n) + " given twice");
  }
  if (p.contains("extra")) {
    for (const auto& [key, value] : p.at("extra").items()) {
      if (out.extra.contains(key) && out.extra[key] != value) {
        throw std::invalid_argument("field 'extra." + key + "' differs between the parts");
      }
      out.extra[key] = value;
    }
  }
  for (const auto& r : p.at("runs")) {
    bounded_int(r.at("index"), "runs[].index", 0, kMaxPartItems);
    eval::RunResult run = run_from_json(r);
    if (!m.run_indices.insert(run.index).second) throw std::invalid_argument("run index " + std::to_string(run.index) + " twice");
    out.runs.push_back(std::move(run));
  }
  for (const auto& s : p.at("free_run")) {
    eval::FreeRunSegment seg;
    seg.index = bounded_int(s.at("index"), "free_run[].index", 0, kMaxPartItems);
    seg.seconds = s.at("seconds").get<double>();
    seg.alarm_times = s.at("alarm_times").get<std::vector<double>>();
    if (!m.segment_indices.insert(seg.index).second) throw std::invalid_argument("free-run segment " + std::to_string(seg.index) + " twice");
    out.free_run.push_back(std::move(seg));
  }
}
}  // namespace

EvaluateFigures merge_partials(const std::vector<std::string>& paths) {
  if (paths.empty()) throw std::invalid_argument("merge: no partial files given");
  EvaluateFigures out;
  MergeState m;
  for (const auto& path : paths) {
    std::ifstream in(path);
    if (!in) throw std::invalid_argument(path + ": cannot open");
    nlohmann::json p;
    try {
      p = nlohmann::json::parse(in);
      merge_part(p, path, m, out);
    } catch (const nlohmann::json::exception& e) {
      throw std::invalid_argument(path + ": not a partial evaluation file (" + std::string(e.what()) + ")");
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(path + ": " + e.what());
    }
  }
  if (static_cast<int>(m.shards_seen.size()) != m.shards) {
    std::string missing;
    for (int k = 1; k <= m.shards; ++k) {
      if (m.shards_seen.count(k) == 0U) missing += (missing.empty() ? "" : ", ") + std::to_string(k);
    }
    throw std::invalid_argument(m.first_path + ": shard(s) " + missing + " of " + std::to_string(m.shards) +
                                " missing (merge needs every part of its campaign)");
  }
  if (out.runs.size() != m.runs_total || out.free_run.size() != m.segments_total) {
    throw std::invalid_argument(m.first_path + ": the parts hold " + std::to_string(out.runs.size()) + " runs and " +
                                std::to_string(out.free_run.size()) + " free-run segments, the campaign has " +
                                std::to_string(m.runs_total) + " and " + std::to_string(m.segments_total));
  }
  std::sort(out.runs.begin(), out.runs.end(), [](const auto& a, const auto& b) { return a.index < b.index; });
  std::sort(out.free_run.begin(), out.free_run.end(), [](const auto& a, const auto& b) { return a.index < b.index; });
  return out;
}

}  // namespace jg::cli
