// Readers of the friction (--friction) and threshold (--threshold) JSON files declared in
// eval/pipeline.hpp. Kept apart from the pipeline so that the fuzz targets (tests/fuzz)
// link the readers without the estimator. Every error is an io::FormatError naming the
// file, the line (syntax errors) and the field ("joints[2].threshold"): nlohmann's own
// messages ("type_error.302", "out_of_range") never reach the user.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

#include "eval/pipeline.hpp"

namespace jg::eval {
namespace {

/// "file:line:column" of a byte offset into the text (1-based, as editors count).
std::string where(const std::string& path, const std::string& text, std::size_t byte) {
  std::size_t line = 1, column = 1;
  for (std::size_t i = 0; i < text.size() && i + 1 < byte; ++i) {
    if (text[i] == '\n') {
      ++line;
      column = 1;
    } else {
      ++column;
    }
  }
  return path + ":" + std::to_string(line) + ":" + std::to_string(column);
}

nlohmann::json read_json(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw io::FormatError(path + ": cannot open");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    // e.byte is one past the offending character; the library's text quotes raw input.
    throw io::FormatError(where(path, text, e.byte) + ": invalid JSON (syntax error or text that is not UTF-8)");
  } catch (const nlohmann::json::out_of_range&) {
    // The parser throws out_of_range.406 (no position) for a number beyond a double, such
    // as 1e999 (found by fuzzing: it escaped as nlohmann's raw message).
    throw io::FormatError(path + ": invalid JSON: a number beyond the range of a double");
  }
}

std::string entry(std::size_t index) { return "joints[" + std::to_string(index) + "]"; }

[[noreturn]] void fail(const std::string& path, const std::string& field, const std::string& problem) {
  throw io::FormatError(path + ": field '" + field + "': " + problem);
}

/// The "joints" array of the file's top-level object, each entry an object.
const nlohmann::json& joints_of(const nlohmann::json& j, const std::string& path) {
  if (!j.is_object()) fail(path, "joints", "the file is not a JSON object {\"joints\": [...]}");
  const auto it = j.find("joints");
  if (it == j.end() || !it->is_array()) fail(path, "joints", "missing or not a list");
  for (std::size_t i = 0; i < it->size(); ++i) {
    if (!(*it)[i].is_object()) fail(path, entry(i), "not an object");
  }
  return *it;
}

/// A finite number; fallback when absent (required when `fallback` is NaN).
double number(const nlohmann::json& e, const char* key, const std::string& path, std::size_t index,
              double fallback = std::numeric_limits<double>::quiet_NaN()) {
  const std::string name = entry(index) + "." + key;
  const auto it = e.find(key);
  if (it == e.end()) {
    if (std::isnan(fallback)) fail(path, name, "missing");
    return fallback;
  }
  if (!it->is_number()) fail(path, name, "not a number");
  const double v = it->get<double>();
  if (!std::isfinite(v)) fail(path, name, "not finite");
  return v;
}

/// For each of `joint_ids`, the index of its entry in the file's "joints" array.
/// `holder`: what the joints belong to, for the message ("the recording", "the model").
std::vector<std::size_t> joint_order(const std::string& path, const std::vector<int>& joint_ids,
                                     const std::string& holder = "the recording") {
  const auto j = read_json(path);
  const auto& a = joints_of(j, path);
  if (a.size() != joint_ids.size()) {
    fail(path, "joints", std::to_string(a.size()) + " entries, " + holder + " has " + std::to_string(joint_ids.size()) + " joints");
  }
  std::vector<std::size_t> order(joint_ids.size(), a.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    int id = joint_ids[i];
    const auto it = a[i].find("joint");
    if (it != a[i].end()) {
      // get<int> would wrap a number beyond int (4294967297 read as joint 1).
      if (!it->is_number_integer() || it->get<std::int64_t>() < 0 || it->get<std::int64_t>() > 1000) {
        fail(path, entry(i) + ".joint", "not a joint number (an integer in 0..1000)");
      }
      id = static_cast<int>(it->get<std::int64_t>());
    }
    const auto found = std::find(joint_ids.begin(), joint_ids.end(), id);
    if (found == joint_ids.end()) fail(path, entry(i) + ".joint", "joint " + std::to_string(id) + " is not in " + holder);
    const auto k = static_cast<std::size_t>(found - joint_ids.begin());
    if (order[k] != a.size()) fail(path, entry(i) + ".joint", "joint " + std::to_string(id) + " given twice");
    order[k] = i;
  }
  return order;
}
/// The per-joint friction of `identify --rigid-body`'s JSON ({"coulomb", "viscous"}: a
/// smoothed Coulomb + viscous law) as LuGre parameters: tau_c = tau_s = coulomb (no Stribeck
/// excess: the fit has none), sigma2 = viscous, sigma1 = 0, and a bristle stiffness that
/// deflects kRigidBristleRad at tau_c (the fit's tanh smoothing is of that order, and at
/// 1 mrad sigma0 dt stays well inside Q16.16 at 100 Hz-1 kHz). w_s only shapes the
/// Stribeck excess, zero here; any positive value gives the same law.
LuGreParams<double> lugre_from_rigid_body(const nlohmann::json& f, const std::string& path, std::size_t i) {
  constexpr double kRigidBristleRad = 1e-3;
  const double coulomb = number(f, "coulomb", path, i);
  const double viscous = number(f, "viscous", path, i);
  if (!(coulomb > 0.0) || viscous < 0.0) {
    fail(path, entry(i) + ".friction", "coulomb must be > 0 and viscous >= 0 [N·m, N·m·s/rad]");
  }
  return LuGreParams<double>{coulomb / kRigidBristleRad, 0.0, viscous, coulomb, coulomb, 0.01};
}
}  // namespace

std::vector<LuGreParams<double>> read_friction_json(const std::string& path) {
  const auto j = read_json(path);
  const auto& a = joints_of(j, path);
  std::vector<LuGreParams<double>> out;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const auto& e = a[i];
    if (!e.contains("sigma0") && e.contains("friction") && e["friction"].is_object()) {
      out.push_back(lugre_from_rigid_body(e["friction"], path, i));
      continue;
    }
    LuGreParams<double> p{number(e, "sigma0", path, i), number(e, "sigma1", path, i), number(e, "sigma2", path, i),
                          number(e, "tau_c", path, i),  number(e, "tau_s", path, i),  number(e, "w_s", path, i)};
    if (validate(p) != Error::ok) {
      fail(path, entry(i), "invalid LuGre parameters (sigma0, tau_c, tau_s, w_s > 0; sigma1, sigma2 >= 0)");
    }
    out.push_back(p);
  }
  return out;
}

std::vector<LuGreParams<double>> read_friction_json(const std::string& path, const std::vector<int>& joint_ids) {
  const auto order = joint_order(path, joint_ids);
  const auto all = read_friction_json(path);
  std::vector<LuGreParams<double>> out;
  for (const std::size_t i : order) out.push_back(all[i]);
  return out;
}

std::vector<LuGreParams<double>> read_friction_json_for_model(const std::string& path, std::size_t joints) {
  std::vector<int> ids(joints);
  for (std::size_t j = 0; j < joints; ++j) ids[j] = static_cast<int>(j + 1);
  const auto order = joint_order(path, ids, "the model");
  const auto all = read_friction_json(path);
  std::vector<LuGreParams<double>> out;
  for (const std::size_t i : order) out.push_back(all[i]);
  return out;
}

Thresholds read_threshold_json(const std::string& path) {
  const auto j = read_json(path);
  const auto& a = joints_of(j, path);
  Thresholds t;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const auto& e = a[i];
    t.threshold.push_back(number(e, "threshold", path, i));
    t.threshold_uncompensated.push_back(number(e, "threshold_uncompensated", path, i, 0.0));
    t.low_speed_extra.push_back(number(e, "low_speed_extra", path, i, 0.0));
    t.low_speed_width = number(e, "low_speed_width", path, i, t.low_speed_width);
    if (!(t.threshold.back() > 0.0)) fail(path, entry(i) + ".threshold", "must be > 0");
    if (t.threshold_uncompensated.back() < 0.0) fail(path, entry(i) + ".threshold_uncompensated", "must be >= 0");
    if (t.low_speed_extra.back() < 0.0) fail(path, entry(i) + ".low_speed_extra", "must be >= 0");
    // The detector divides by the width (1 / w_band): 0 would make the band infinite.
    if (!(t.low_speed_width > 0.0)) fail(path, entry(i) + ".low_speed_width", "must be > 0 [rad/s]");
    // The holding detector's change threshold (calibrate/evaluate write it): all joints or none.
    if (e.contains("hold_change_threshold")) {
      if (t.hold_change.size() != i) fail(path, entry(i) + ".hold_change_threshold", "given for some joints only");
      t.hold_change.push_back(number(e, "hold_change_threshold", path, i));
      if (!(t.hold_change.back() >= 0.0)) fail(path, entry(i) + ".hold_change_threshold", "must be >= 0 (0: off)");
    }
    // The calibration's region (calibrate writes it): all joints or none.
    if (e.contains("region")) {
      if (t.q_min.size() != i) fail(path, entry(i) + ".region", "given for some joints only");
      const auto& g = e["region"];
      if (!g.is_object()) fail(path, entry(i) + ".region", "not an object {q_min, q_max, dq_max, ddq_max}");
      t.q_min.push_back(number(g, "q_min", path, i));
      t.q_max.push_back(number(g, "q_max", path, i));
      t.dq_max.push_back(number(g, "dq_max", path, i));
      t.ddq_max.push_back(number(g, "ddq_max", path, i));
      t.stop_gain.push_back(number(e, "stop_gain", path, i, 0.0));
      if (!(t.q_min.back() <= t.q_max.back())) fail(path, entry(i) + ".region.q_min", "must be <= q_max");
      if (t.dq_max.back() < 0.0 || t.ddq_max.back() < 0.0 || t.stop_gain.back() < 0.0) {
        fail(path, entry(i) + ".region", "dq_max, ddq_max and stop_gain must be >= 0");
      }
    }
  }
  if (!t.q_min.empty() && t.q_min.size() != t.threshold.size()) fail(path, "region", "given for some joints only");
  if (!t.hold_change.empty() && t.hold_change.size() != t.threshold.size()) {
    fail(path, "hold_change_threshold", "given for some joints only");
  }
  for (const char* key : {"hold_settle_s", "hold_reference_s"}) {
    if (!j.contains(key)) continue;
    if (!j[key].is_number() || !(j[key].get<double>() >= 0.0) || !(j[key].get<double>() <= 10.0)) {
      fail(path, key, "must be a number of seconds in [0, 10]");
    }
    (std::string(key) == "hold_settle_s" ? t.hold_settle_s : t.hold_reference_s) = j[key].get<double>();
  }
  return t;
}

Thresholds read_threshold_json(const std::string& path, const std::vector<int>& joint_ids) {
  const auto order = joint_order(path, joint_ids);
  const Thresholds all = read_threshold_json(path);
  Thresholds out = all;
  for (auto [dst, src] : {std::pair{&out.threshold, &all.threshold}, {&out.threshold_uncompensated, &all.threshold_uncompensated},
                          {&out.low_speed_extra, &all.low_speed_extra}, {&out.hold_change, &all.hold_change},
                          {&out.q_min, &all.q_min}, {&out.q_max, &all.q_max}, {&out.dq_max, &all.dq_max},
                          {&out.ddq_max, &all.ddq_max}, {&out.stop_gain, &all.stop_gain}}) {
    if (src->size() != order.size()) continue;  // optional fields the file does not give
    for (std::size_t k = 0; k < order.size(); ++k) (*dst)[k] = (*src)[order[k]];
  }
  return out;
}

}  // namespace jg::eval
