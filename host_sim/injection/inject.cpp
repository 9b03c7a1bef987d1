#include "injection/inject.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <utility>

#include "injection/csv_edit.hpp"
#include "injection/effects_file.hpp"
#include "io/sha256.hpp"

namespace jg::inject {
namespace {

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw io::FormatError(path + ": cannot open");
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

/// The column prefix the reader took the torque from (tau_m<j> re-read as a torque sensor's
/// under --torque-kind joint when the file has no tau_j<j>).
std::string torque_prefix(io::TorqueKind kind, const std::string& text, const std::vector<int>& joint_ids) {
  if (kind == io::TorqueKind::current) return "i";
  if (kind == io::TorqueKind::tau_m) return "tau_m";
  const std::string header = text.substr(0, text.find('\n'));
  return has_joint_column(header, joint_ids, "tau_j") ? "tau_j" : "tau_m";
}

/// Linear interpolation on a uniform segment's grid, held at its ends.
double on_grid(const SegmentAddition& a, std::size_t j, double t) {
  const auto& g = a.t;
  if (t <= g.front()) return a.added_nm[j].front();
  if (t >= g.back()) return a.added_nm[j].back();
  const auto i = static_cast<std::size_t>(std::upper_bound(g.begin(), g.end(), t) - g.begin()) - 1;
  const double w = (t - g[i]) / (g[i + 1] - g[i]);
  return a.added_nm[j][i] + w * (a.added_nm[j][i + 1] - a.added_nm[j][i]);
}

/// Whether any effect needs N·m turned into the column's unit (all but a pure scale).
bool needs_torque_constant(const std::vector<robot::PlantEffect>& effects) {
  return std::any_of(effects.begin(), effects.end(), [](const auto& e) { return channel_of(e) != Channel::scale; });
}

/// What the effects of a row's own state add at the row of time `t` (`at_rows`: [joint][row]
/// over the recording as read); 0 without them.
double at_row(const InjectRequest& r, const std::vector<std::vector<double>>& at_rows, std::size_t j, double t) {
  if (at_rows.empty() || at_rows[j].empty()) return 0.0;
  const auto& times = r.rows->t;
  const auto it = std::lower_bound(times.begin(), times.end(), t);
  if (it == times.end() || *it != t) throw std::logic_error("inject: no row at t = " + std::to_string(t) + " s in the recording as read");
  return at_rows[j][static_cast<std::size_t>(it - times.begin())];
}

/// Per row: the segment whose span holds its time, the added torque interpolated there (and
/// what the row's own state adds), the sensor's scale and offset; in A for currents (divided by K_I).
RowRule row_rule(const InjectRequest& r, const std::vector<SegmentAddition>& added, const std::vector<std::vector<double>>& at_rows,
                 const SensorChange& sensor) {
  const auto& spans = r.data->report.segments;
  const bool current = r.torque == io::TorqueKind::current;
  return [&r, &added, &at_rows, &sensor, &spans, current](double t, const std::vector<double>& old, std::vector<double>& out) {
    std::size_t s = 0;
    while (s < spans.size() && !(t >= spans[s].t_begin && t <= spans[s].t_end)) ++s;
    if (s == spans.size() || s >= added.size()) return false;
    for (std::size_t j = 0; j < old.size(); ++j) {
      const double unit = current ? r.model.torque_constant[j] : 1.0;  // N·m per column unit
      const double added_nm = on_grid(added[s], j, t) + at_row(r, at_rows, j, t);
      out[j] = sensor.scale[j] * (old[j] + added_nm / unit) + sensor.offset_nm[j] / unit;
    }
    return true;
  };
}

/// The effects computed at the rows as read (rows_added), and those on the uniform grid.
std::pair<std::vector<robot::PlantEffect>, std::vector<robot::PlantEffect>> rows_and_grid(const InjectRequest& r) {
  const bool delayed = std::any_of(r.effects.begin(), r.effects.end(), [](const auto& e) { return channel_of(e) == Channel::delay; });
  std::vector<robot::PlantEffect> rows, grid;
  for (const auto& e : r.effects) (r.rows != nullptr && !delayed && acts_on_the_row_alone(e) ? rows : grid).push_back(e);
  return {rows, grid};
}

}  // namespace

std::string side_file_path(const std::string& csv_path) {
  const std::filesystem::path p(csv_path);
  return (p.parent_path() / (p.stem().string() + ".json")).string();
}

InjectResult inject(const InjectRequest& r) {
  InjectResult res;
  const std::string text = read_text(r.recording_path);
  res.source_sha256 = io::sha256_hex(text);
  res.unit = r.torque == io::TorqueKind::current ? "A" : "N·m";
  if (r.data == nullptr || r.data->segments.empty()) throw std::invalid_argument("no uniform segment to work on");
  if (r.effects.empty()) {
    res.text = text;  // `plant_effects: []`: the recording as it was, byte for byte
    res.data_rows = r.data->report.rows_in;
    return res;
  }
  const io::Recording& first = r.data->segments.front();
  if (r.torque == io::TorqueKind::current && !r.torque_constant_known && needs_torque_constant(r.effects)) {
    throw std::invalid_argument("its torque is motor current (i<j>) and the URDF gives no torque constant to turn the effects' "
                                "N·m into A: give --drive FILE with k_i");
  }
  const auto [on_rows, on_grid_only] = rows_and_grid(r);
  const std::vector<SegmentAddition> added = physics_added(r.data->segments, r.model, on_grid_only);
  const std::vector<std::vector<double>> at_rows = on_rows.empty() ? std::vector<std::vector<double>>{}
                                                                    : rows_added(*r.rows, on_rows, r.data->report.step_s);
  const SensorChange sensor = sensor_change(r.effects, first.joints());
  // Where the regularizer dropped rows repeating a state (a jittered logger's), they must stay repeats.
  res.repeats_follow_state = r.data->report.method.rfind("none", 0) != 0 && r.data->report.repeats_dropped > 0;
  const EditedCsv e = edit_torque_columns(text, r.recording_path, first.joint_ids, torque_prefix(r.torque, text, first.joint_ids),
                                          res.repeats_follow_state, row_rule(r, added, at_rows, sensor));
  res.text = e.text;
  res.data_rows = e.data_rows;
  res.rows_outside = e.rows_outside;
  std::size_t samples = 0;
  for (const auto& a : added) samples += a.t.size();
  for (std::size_t j = 0; j < e.columns.size(); ++j) {
    double ss = 0.0;
    for (const auto& a : added) ss += j < a.delay_on_model_ss.size() ? a.delay_on_model_ss[j] : 0.0;
    const double unit = r.torque == io::TorqueKind::current ? r.model.torque_constant[j] : 1.0;  // N·m per column unit
    const double delay_rms = samples > 0 ? std::sqrt(ss / static_cast<double>(samples)) / unit : 0.0;
    res.joints.push_back({first.joint_ids[j], e.columns[j], e.rows_changed[j], e.max_abs_change[j], e.rms_change[j], delay_rms});
  }
  return res;
}

nlohmann::json side_file(const InjectRequest& r, const InjectResult& result,
                         const std::vector<std::pair<std::string, std::string>>& inputs) {
  nlohmann::json j = nlohmann::json::object();
  const std::string source_side = side_file_path(r.recording_path);
  const bool source_side_ours = io::classify_side_file(source_side) == io::SideFile::ours;
  if (source_side_ours) j = nlohmann::json::parse(read_text(source_side));  // the reader checked it
  j["format"] = io::kSideFileFormat;  // the reader takes it as jointguard's (io/recording.hpp)
  nlohmann::json effects = nlohmann::json::array();
  for (const auto& e : r.effects) {
    effects.push_back(
        {{"effect", e.effect}, {"joint", e.joint}, {"setting", e.setting}, {"coefficients", e.coefficients}, {"params", e.params}});
  }
  nlohmann::json files = nlohmann::json::object();
  for (const auto& [name, path] : inputs) {
    if (!path.empty()) files[name] = {{"path", path}, {"sha256", io::sha256_hex(read_text(path))}};
  }
  nlohmann::json changed = nlohmann::json::array();
  for (const auto& c : result.joints) {
    changed.push_back({{"joint", c.joint}, {"column", c.column}, {"rows_changed", c.rows_changed},
                       {"max_abs_change", c.max_abs_change}, {"rms_change", c.rms_change}});
    if (c.delay_on_model_rms > 0.0) changed.back()["delay_on_model_rms"] = c.delay_on_model_rms;
  }
  nlohmann::json entry{{"tool", "jointguard inject"},
                       {"source", {{"path", r.recording_path}, {"sha256", result.source_sha256}}},
                       {"source_side_file", source_side_ours ? source_side : ""},
                       {"inputs", files},
                       {"torque", io::to_string(r.torque)},
                       {"unit", result.unit},
                       {"plant_effects", effects},
                       {"columns_changed", changed},
                       {"data_rows", result.data_rows},
                       {"rows_outside_segments", result.rows_outside},
                       {"number_format", "changed fields: %.9g, or the source field's significant digits when more"}};
  if (!j.contains("injections") || !j["injections"].is_array()) j["injections"] = nlohmann::json::array();
  j["injections"].push_back(entry);
  return j;
}

}  // namespace jg::inject
