#include "injection/csv_edit.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>

#include "io/recording.hpp"

namespace jg::inject {
namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return {};
  return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

/// "<prefix><digits>" -> the number, else -1 (the reader's rule: q1 and q01 are joint 1).
int joint_of(const std::string& name, const std::string& prefix) {
  if (name.size() <= prefix.size() || name.compare(0, prefix.size(), prefix) != 0) return -1;
  int v = 0;
  for (std::size_t k = prefix.size(); k < name.size(); ++k) {
    if (name[k] < '0' || name[k] > '9' || v > 1000) return -1;
    v = v * 10 + (name[k] - '0');
  }
  return v;
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out(1);
  for (const char c : line) {
    if (c == ',') {
      out.emplace_back();
    } else {
      out.back().push_back(c);
    }
  }
  return out;
}

double parse(const std::string& field) {
  const std::string s = trim(field);
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  return !s.empty() && end == s.c_str() + s.size() && errno != ERANGE ? v : std::nan("");
}

[[noreturn]] void fail(const std::string& path, std::size_t line, const std::string& field, const std::string& what) {
  throw io::FormatError(path + ":" + std::to_string(line) + ": " + (field.empty() ? "" : "field '" + field + "': ") + what);
}

/// The header's columns this edit reads: time, the torque columns (joint order) and every
/// column the regularizer compares to find a repeated state.
struct Layout {
  std::size_t fields = 0;
  std::size_t time = 0;
  std::vector<std::size_t> torque;
  std::vector<std::string> torque_names;
  std::vector<std::size_t> state;
};

Layout layout_of(const std::string& header, const std::string& path, const std::vector<int>& joint_ids, const std::string& prefix) {
  const std::vector<std::string> names = split(header);
  Layout l;
  l.fields = names.size();
  l.torque.assign(joint_ids.size(), names.size());
  l.torque_names.resize(joint_ids.size());
  bool time = false;
  for (std::size_t c = 0; c < names.size(); ++c) {
    const std::string name = trim(names[c]);
    if (name == "t") {
      time = true;
      l.time = c;
    }
    for (std::size_t j = 0; j < joint_ids.size(); ++j) {
      if (joint_of(name, prefix) == joint_ids[j]) {
        l.torque[j] = c;
        l.torque_names[j] = name;
      }
      for (const char* p : {"q", "dq", "i", "tau_m", "tau_j", "tau_ext"}) {
        if (joint_of(name, p) == joint_ids[j]) l.state.push_back(c);
      }
    }
  }
  if (!time) fail(path, 1, "t", "missing required time column");
  for (std::size_t j = 0; j < joint_ids.size(); ++j) {
    if (l.torque[j] == names.size()) fail(path, 1, prefix + std::to_string(joint_ids[j]), "no such column to inject into");
  }
  return l;
}

std::string join(const std::vector<std::string>& fields) {
  std::string out;
  for (std::size_t c = 0; c < fields.size(); ++c) {
    if (c > 0) out.push_back(',');
    out += fields[c];
  }
  return out;
}

/// The source field with its number replaced, its surrounding spaces kept.
std::string replaced(const std::string& source, double value) {
  const auto b = source.find_first_not_of(" \t");
  const auto e = source.find_last_not_of(" \t");
  if (b == std::string::npos) return format_like(value, source);
  return source.substr(0, b) + format_like(value, source.substr(b, e - b + 1)) + source.substr(e + 1);
}

/// Rows one after the other; remembers the previous row for repeated states.
class RowEditor {
 public:
  RowEditor(Layout l, const RowRule& rule, const std::string& path, bool repeats, EditedCsv& out)
      : l_(std::move(l)), rule_(rule), path_(path), repeats_(repeats), out_(out), sum_sq_(l_.torque.size(), 0.0),
        change_(l_.torque.size(), 0.0) {}

  /// The data row `line` (line number `line_no`) with its torque fields rewritten.
  std::string edit(const std::string& line, std::size_t line_no) {
    std::vector<std::string> fields = split(line);
    if (fields.size() != l_.fields) {
      fail(path_, line_no, "", "expected " + std::to_string(l_.fields) + " fields (file changed while read?)");
    }
    ++out_.data_rows;
    std::vector<double> state;
    for (const std::size_t c : l_.state) state.push_back(parse(fields[c]));
    if (repeats_ && out_.data_rows > 1 && state == previous_state_) {
      for (const std::size_t c : l_.torque) fields[c] = previous_fields_[c];  // the same state, the same reading
    } else {
      kept_ = !apply_rule(fields, line_no);
    }
    out_.rows_outside += kept_ ? 1 : 0;
    for (std::size_t j = 0; j < change_.size(); ++j) count(j, change_[j]);
    previous_state_ = std::move(state);
    previous_fields_ = fields;
    return join(fields);
  }

  void finish() {
    out_.rms_change.resize(sum_sq_.size());
    for (std::size_t j = 0; j < sum_sq_.size(); ++j) {
      out_.rms_change[j] = out_.rows_changed[j] > 0 ? std::sqrt(sum_sq_[j] / static_cast<double>(out_.rows_changed[j])) : 0.0;
    }
  }

 private:
  /// The rule on this row; false when it leaves the row as it is. Sets change_.
  bool apply_rule(std::vector<std::string>& fields, std::size_t line_no) {
    std::vector<double> before(l_.torque.size()), after(l_.torque.size());
    for (std::size_t j = 0; j < l_.torque.size(); ++j) before[j] = parse(fields[l_.torque[j]]);
    std::fill(change_.begin(), change_.end(), 0.0);
    if (!rule_(parse(fields[l_.time]), before, after)) return false;
    for (std::size_t j = 0; j < l_.torque.size(); ++j) {
      if (after[j] == before[j]) continue;  // nothing added here: the text stays as it is
      if (!std::isfinite(after[j])) fail(path_, line_no, l_.torque_names[j], "the injected value is not finite (effects too large?)");
      std::string text = replaced(fields[l_.torque[j]], after[j]);
      if (text == fields[l_.torque[j]]) continue;  // a change below the printed digits: the field as it was
      fields[l_.torque[j]] = std::move(text);
      change_[j] = after[j] - before[j];
    }
    return true;
  }
  void count(std::size_t j, double change) {
    if (change == 0.0) return;
    ++out_.rows_changed[j];
    out_.max_abs_change[j] = std::max(out_.max_abs_change[j], std::fabs(change));
    sum_sq_[j] += change * change;
  }

  Layout l_;
  const RowRule& rule_;
  const std::string& path_;
  bool repeats_;
  EditedCsv& out_;
  std::vector<double> sum_sq_, change_, previous_state_;
  std::vector<std::string> previous_fields_;
  bool kept_ = false;
};

}  // namespace

std::string format_like(double value, const std::string& source) {
  // Significant digits the source was written with: its mantissa without sign, point and
  // leading zeros.
  int digits = 0;
  bool leading = true;
  for (const char c : source) {
    if (c == 'e' || c == 'E') break;
    if (c < '0' || c > '9') continue;
    if (leading && c == '0') continue;
    leading = false;
    ++digits;
  }
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.*g", std::clamp(digits, 9, 17), value);
  return buf;
}

bool has_joint_column(const std::string& header_line, const std::vector<int>& joint_ids, const std::string& prefix) {
  for (const auto& name : split(header_line)) {
    const int j = joint_of(trim(name), prefix);
    if (std::find(joint_ids.begin(), joint_ids.end(), j) != joint_ids.end()) return true;
  }
  return false;
}

EditedCsv edit_torque_columns(const std::string& text, const std::string& path, const std::vector<int>& joint_ids,
                              const std::string& prefix, bool same_state_repeats, const RowRule& rule) {
  EditedCsv out;
  out.text.reserve(text.size() + text.size() / 4);
  out.rows_changed.assign(joint_ids.size(), 0);
  out.max_abs_change.assign(joint_ids.size(), 0.0);
  std::optional<RowEditor> rows;
  std::size_t line_no = 0;
  for (std::size_t pos = 0; pos < text.size();) {
    // Each line's end kept as it was ("\n", "\r\n", or none on a last line).
    const std::size_t nl = text.find('\n', pos);
    const std::size_t end = nl == std::string::npos ? text.size() : nl;
    std::string line = text.substr(pos, end - pos);
    const bool cr = !line.empty() && line.back() == '\r';
    if (cr) line.pop_back();
    pos = end + 1;
    ++line_no;
    if (line_no == 1) {
      Layout l = layout_of(line, path, joint_ids, prefix);
      out.columns = l.torque_names;
      rows.emplace(std::move(l), rule, path, same_state_repeats, out);
    } else if (!trim(line).empty()) {  // blank lines, as the reader skips them, stay
      line = rows->edit(line, line_no);
    }
    out.text += line;
    if (cr) out.text += '\r';
    if (nl != std::string::npos) out.text += '\n';
  }
  if (rows) rows->finish();
  return out;
}

}  // namespace jg::inject
