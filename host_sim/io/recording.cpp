#include "io/recording.hpp"

#include "io/atomic_write.hpp"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

namespace jg::io {
namespace {

/// A field quoted in a message: printable ASCII only (others as '?'), at most 40
/// characters, so that a binary file does not write raw bytes to the terminal.
std::string printable(const std::string& text) {
  std::string out;
  for (const char c : text.substr(0, 40)) out.push_back(c >= 0x20 && c < 0x7F ? c : '?');
  return text.size() > 40 ? out + "..." : out;
}
std::string quote(const std::string& text) { return "'" + printable(text) + "'"; }

[[noreturn]] void fail(const std::string& file, std::size_t line, const std::string& field,
                       const std::string& what) {
  std::ostringstream os;
  os << file << ':' << line << ": ";
  if (!field.empty()) {
    os << "field '" << printable(field) << "': ";
  }
  os << what;
  throw FormatError(os.str());
}

std::vector<std::string> split_commas(const std::string& line) {
  std::vector<std::string> out;
  std::string cur;
  for (const char c : line) {
    if (c == ',') {
      out.push_back(cur);
      cur.clear();
    } else if (c != '\r') {
      cur.push_back(c);
    }
  }
  out.push_back(cur);
  return out;
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) {
    return {};
  }
  const auto e = s.find_last_not_of(" \t");
  return s.substr(b, e - b + 1);
}

/// "<prefix><digits>" -> digits as int, else -1.
int joint_suffix(const std::string& name, const std::string& prefix) {
  if (name.size() <= prefix.size() || name.compare(0, prefix.size(), prefix) != 0) {
    return -1;
  }
  int v = 0;
  for (std::size_t k = prefix.size(); k < name.size(); ++k) {
    if (name[k] < '0' || name[k] > '9' || v > 1000) {
      return -1;
    }
    v = v * 10 + (name[k] - '0');
  }
  return v;
}

bool parse_double(const std::string& tok, double& out) {
  const std::string s = trim(tok);
  if (s.empty()) {
    return false;
  }
  errno = 0;
  char* end = nullptr;
  out = std::strtod(s.c_str(), &end);
  return end == s.c_str() + s.size() && errno != ERANGE && std::isfinite(out);
}

std::string replace_j(std::string pattern, int j) {
  const auto pos = pattern.find("{j}");
  if (pos != std::string::npos) {
    pattern.replace(pos, 3, std::to_string(j));
  }
  return pattern;
}

enum class Kind { time, q, dq, current, tau_m, tau_j, tau_ext, collision, extra };
struct Column {
  Kind kind = Kind::extra;
  std::size_t joint = 0;  // index into joint_ids
  std::string name;
};

/// The side file's text parsed; a syntax error throws FormatError with line and column.
nlohmann::json parse_side_file(const std::filesystem::path& json_path, const std::string& text) {
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    // Line and column of e.byte (one past the offending character); nlohmann's own text
    // quotes the raw input and its exception id, which tell the user nothing.
    std::size_t line = 1, column = 1;
    for (std::size_t i = 0; i < text.size() && i + 1 < e.byte; ++i) {
      column = text[i] == '\n' ? 1 : column + 1;
      line += text[i] == '\n' ? 1 : 0;
    }
    throw FormatError(json_path.string() + ":" + std::to_string(line) + ":" + std::to_string(column) +
                      ": invalid JSON (syntax error or text that is not UTF-8)");
  } catch (const nlohmann::json::out_of_range&) {  // out_of_range.406: a number beyond a double
    throw FormatError(json_path.string() + ": invalid JSON: a number beyond the range of a double");
  }
}

std::string read_text_file(const std::filesystem::path& path, bool& found) {
  std::ifstream in(path, std::ios::binary);
  found = static_cast<bool>(in) && !std::filesystem::is_directory(path);
  if (!found) return {};
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

/// Ours: the format key, or (files of versions before it) an object holding only the keys
/// jointguard wrote. A text that names jointguard but does not parse is ours and broken.
SideFile classify(const std::filesystem::path& json_path, const std::string& text, std::string* why) {
  nlohmann::json j;
  try {
    j = parse_side_file(json_path, text);
  } catch (const FormatError& e) {
    if (text.find("jointguard") != std::string::npos) return SideFile::ours;
    if (why) *why = e.what();
    return SideFile::foreign;
  }
  if (j.is_object() && j.contains("format")) {
    if (j["format"] == kSideFileFormat) return SideFile::ours;
    if (why) *why = json_path.string() + ": \"format\" is not \"" + kSideFileFormat + "\"";
    return SideFile::foreign;
  }
  static const std::set<std::string> legacy = {"model", "sample_time", "scenario", "seed", "injections"};
  bool only_ours = j.is_object() && !j.empty();
  if (only_ours) {
    for (const auto& kv : j.items()) only_ours = only_ours && legacy.count(kv.key()) != 0U;
  }
  if (only_ours) return SideFile::ours;
  if (why) *why = json_path.string() + ": no \"format\": \"" + kSideFileFormat + "\" key";
  return SideFile::foreign;
}

/// The side file's metadata; another program's file of the same name is ignored with a note.
RecordingMeta read_meta(const std::filesystem::path& json_path, std::vector<std::string>& notes) {
  RecordingMeta meta;
  bool found = false;
  const std::string text = read_text_file(json_path, found);
  if (!found) return meta;
  std::string why;
  if (classify(json_path, text, &why) == SideFile::foreign) {
    notes.push_back(json_path.string() + " is not a jointguard side file (" + why + "): ignored");
    return meta;
  }
  const nlohmann::json j = parse_side_file(json_path, text);
  if (!j.is_object()) throw FormatError(json_path.string() + ": expected a JSON object {\"model\": ..., \"sample_time\": ...}");
  auto field = [&](const char* key, auto& dst) {
    if (j.contains(key) && !j[key].is_null()) {
      try {
        dst = j[key].get<std::decay_t<decltype(dst)>>();
      } catch (const nlohmann::json::exception&) {
        throw FormatError(json_path.string() + ": field '" + key + "': wrong type");
      }
    }
  };
  field("model", meta.model);
  field("sample_time", meta.sample_time);
  field("scenario", meta.scenario);
  if (!std::isfinite(meta.sample_time) || meta.sample_time < 0.0) {
    throw FormatError(json_path.string() + ": field 'sample_time': must be >= 0 [s] (0 = unknown)");
  }
  if (j.contains("seed") && j["seed"].is_number_unsigned()) {
    meta.seed = j["seed"].get<unsigned long long>();
  }
  if (j.contains("identity") && j["identity"].is_object()) meta.identity_json = j["identity"].dump();
  return meta;
}

/// Ratios dq / (change of q over t) where the joint clearly moves: |dq| at least a fifth of
/// its largest, and q changing by more than an encoder's resolution.
void velocity_ratios(const Recording& rec, std::size_t j, std::vector<double>& out) {
  const auto& q = rec.q[j];
  const auto& dq = rec.dq[j];
  double dq_max = 0.0;
  for (const double v : dq) dq_max = std::max(dq_max, std::fabs(v));
  if (!(dq_max > 0.0)) return;
  for (std::size_t k = 1; k + 1 < rec.samples(); ++k) {
    const double dt = rec.t[k + 1] - rec.t[k - 1];
    const double step = q[k + 1] - q[k - 1];
    if (!(dt > 0.0) || std::fabs(step) < 1e-6 || std::fabs(dq[k]) < 0.2 * dq_max) continue;
    out.push_back(dq[k] / (step / dt));
  }
}

/// A time column in another unit than seconds (milliseconds from a logger, most often)
/// makes every rate and derivative wrong by that factor while everything still runs. With
/// both q and dq, dq against the change of q over t tells: refused when that ratio is
/// consistent over the motion (quartiles within a factor 4) and far from 1.
void check_time_unit(const Recording& rec, const std::string& path, const std::string& time_column) {
  std::vector<double> r;
  for (std::size_t j = 0; j < rec.joints() && j < rec.q.size() && j < rec.dq.size(); ++j) velocity_ratios(rec, j, r);
  constexpr std::size_t kMinSamples = 50;
  if (r.size() < kMinSamples) return;
  std::sort(r.begin(), r.end());
  const double q1 = r[r.size() / 4], median = r[r.size() / 2], q3 = r[3 * r.size() / 4];
  if (!(q1 > 0.0) || q3 > 4.0 * q1) return;  // no consistent ratio: the check cannot tell
  constexpr double kFar = 20.0;              // a unit slip is a factor 60 or 1000, not 1.x
  if (median < kFar && median > 1.0 / kFar) return;
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.4g", median);
  const double l = std::log10(median);
  const char* unit = std::fabs(l - 3.0) < 0.3 ? "milliseconds" : std::fabs(l - 6.0) < 0.3 ? "microseconds"
                   : std::fabs(l + std::log10(60.0)) < 0.2 ? "minutes" : "another unit than seconds";
  fail(path, 1, time_column,
       std::string("the velocities dq are ") + buf + " times the change of q over t (median of " + std::to_string(r.size()) +
           " samples): the time stamps look like " + unit + "; give t in seconds (or dq in rad/s)");
}

/// Applies the user's torque choice; the columns it needs must be there.
void resolve_torque(Recording& rec, const std::string& path, TorqueChoice choice) {
  const std::string first = rec.joint_ids.empty() ? "1" : std::to_string(rec.joint_ids.front());
  switch (choice) {
    case TorqueChoice::automatic:
      rec.torque_kind = !rec.tau_j.empty() ? TorqueKind::tau_j : (!rec.tau_m.empty() ? TorqueKind::tau_m : TorqueKind::current);
      return;
    case TorqueChoice::current:
      if (rec.current.empty()) fail(path, 1, "i" + first, "--torque-kind current needs motor current columns i<j>");
      rec.torque_kind = TorqueKind::current;
      return;
    case TorqueChoice::motor:
      if (rec.tau_m.empty()) fail(path, 1, "tau_m" + first, "--torque-kind motor needs motor torque columns tau_m<j>");
      rec.torque_kind = TorqueKind::tau_m;
      return;
    case TorqueChoice::joint:
      if (rec.tau_j.empty()) {
        if (rec.tau_m.empty()) {
          fail(path, 1, "tau_j" + first, "--torque-kind joint needs joint torque columns tau_j<j> (or tau_m<j> to re-read)");
        }
        // The logger wrote a torque sensor's reading under tau_m<j> (e.g. a Panda's tau_J).
        rec.tau_j = std::move(rec.tau_m);
        rec.tau_m.clear();
      }
      rec.torque_kind = TorqueKind::tau_j;
      return;
  }
}

}  // namespace

const char* to_string(TorqueKind kind) {
  switch (kind) {
    case TorqueKind::current: return "i";
    case TorqueKind::tau_m: return "tau_m";
    case TorqueKind::tau_j: return "tau_j";
  }
  return "?";
}

TorqueChoice parse_torque_choice(const std::string& text) {
  if (text == "auto") return TorqueChoice::automatic;
  if (text == "current") return TorqueChoice::current;
  if (text == "motor") return TorqueChoice::motor;
  if (text == "joint") return TorqueChoice::joint;
  throw std::invalid_argument("--torque-kind must be auto, current, motor or joint (got '" + text + "')");
}

const std::vector<std::vector<double>>& torque_columns(const Recording& rec) {
  switch (rec.torque_kind) {
    case TorqueKind::current: return rec.current;
    case TorqueKind::tau_m: return rec.tau_m;
    case TorqueKind::tau_j: return rec.tau_j;
  }
  return rec.tau_m;
}

void Recording::resize(std::size_t n_joints, std::size_t n_samples, bool with_current, bool with_tau_m,
                       bool with_tau_ext, bool with_collision) {
  joint_ids.resize(n_joints);
  for (std::size_t k = 0; k < n_joints; ++k) {
    joint_ids[k] = static_cast<int>(k + 1);
  }
  t.assign(n_samples, 0.0);
  // Each signal zero-filled in place (copying one zero block into each cost as much again).
  auto zeros = [&](std::vector<std::vector<double>>& sig, bool wanted) {
    sig.clear();
    if (wanted) {
      sig.resize(n_joints);
      for (auto& v : sig) v.assign(n_samples, 0.0);
    }
  };
  zeros(q, true);
  zeros(dq, true);
  zeros(current, with_current);
  zeros(tau_m, with_tau_m);
  tau_j.clear();
  torque_kind = with_tau_m || !with_current ? TorqueKind::tau_m : TorqueKind::current;
  zeros(tau_ext, with_tau_ext);
  collision = with_collision ? std::vector<int>(n_samples, 0) : std::vector<int>{};
}

namespace {
/// A header that is not comma-separated, unquoted CSV (the recording contract's dialect):
/// refused naming the dialect it looks like, not as "no joint position column".
void check_dialect(const std::string& path, const std::string& line, const std::vector<std::string>& header) {
  if (header.size() == 1) {
    for (const char sep : {';', '\t', '|'}) {
      if (line.find(sep) == std::string::npos) continue;
      const std::string name = sep == '\t' ? "tabs" : std::string("'") + sep + "'";
      fail(path, 1, "", "the header is separated by " + name + ": recordings are comma-separated CSV (t,q1,...,dq1,...)");
    }
  }
  for (const auto& raw : header) {
    const std::string name = trim(raw);
    if (!name.empty() && (name.front() == '"' || name.front() == '\'')) {
      fail(path, 1, name, "quoted column names are not read: write the header without quotes (t,q1,...)");
    }
  }
}

/// The header's columns: each one's kind and joint, and which optional kinds are present.
struct Header {
  std::vector<Column> cols;
  bool has_time = false, has_current = false, has_tau_m = false, has_tau_j = false, has_tau_ext = false;
};

/// The joints the header's position columns name (q1, q2, ...); none: the file is refused,
/// naming the dialect if it is not comma-separated, unquoted CSV.
std::set<int> position_joints(const std::string& path, const std::string& line, const std::vector<std::string>& header) {
  std::set<int> q_ids;
  for (const auto& raw : header) {
    const int j = joint_suffix(trim(raw), "q");
    if (j >= 0) {
      q_ids.insert(j);
    }
  }
  if (q_ids.empty()) {
    check_dialect(path, line, header);
    fail(path, 1, "q<j>", "no joint position column (q1, q2, ...)");
  }
  return q_ids;
}

/// Each header column's kind and joint (a column of no known kind is an extra signal).
Header classify_columns(const std::string& path, const std::vector<std::string>& header, const ReadOptions& options,
                        const Recording& rec, std::map<int, std::size_t>& joint_index) {
  Header h;
  std::set<std::string> seen;
  std::map<std::pair<int, int>, std::string> per_joint;  ///< (column kind, joint) -> its column's name
  for (const auto& raw : header) {
    Column c;
    c.name = trim(raw);
    if (c.name.empty()) {
      fail(path, 1, "", "empty column name in header");
    }
    if (!seen.insert(c.name).second) {
      fail(path, 1, c.name, "duplicate column");
    }
    auto match = [&](const char* prefix, Kind kind) {
      const int j = joint_suffix(c.name, prefix);
      if (j >= 0 && joint_index.count(j) != 0U) {
        // q1 and q01 both name joint 1: refused, not read interleaved.
        const auto first = per_joint.emplace(std::make_pair(static_cast<int>(kind), j), c.name);
        if (!first.second) fail(path, 1, c.name, "joint " + std::to_string(j) + " given twice (also '" + first.first->second + "')");
        c.kind = kind;
        c.joint = joint_index[j];
        return true;
      }
      return false;
    };
    if (c.name == options.time_column) {
      c.kind = Kind::time;
      h.has_time = true;
    } else if (c.name == "collision") {
      c.kind = Kind::collision;
    } else if (match("tau_ext", Kind::tau_ext)) {
      h.has_tau_ext = true;
    } else if (match("tau_m", Kind::tau_m)) {
      h.has_tau_m = true;
    } else if (match("tau_j", Kind::tau_j)) {
      h.has_tau_j = true;
    } else if (match("dq", Kind::dq) || match("q", Kind::q)) {
    } else if (match("i", Kind::current)) {
      h.has_current = true;
    } else {
      for (const int j : rec.joint_ids) {
        if (!options.torque_column_pattern.empty() && c.name == replace_j(options.torque_column_pattern, j)) {
          c.kind = Kind::tau_m;
          c.joint = joint_index[j];
          h.has_tau_m = true;
        }
      }
    }
    h.cols.push_back(c);
  }
  if (!h.has_time) {
    fail(path, 1, options.time_column, "missing required time column");
  }
  return h;
}

/// Every joint needs dq and a torque source, and a kind given for one joint for all.
void check_joint_columns(const std::string& path, const Header& h, const Recording& rec,
                         std::map<int, std::size_t>& joint_index) {
  for (const int j : rec.joint_ids) {
    const std::size_t k = joint_index[j];
    auto has = [&](Kind kind) {
      for (const auto& c : h.cols) {
        if (c.kind == kind && c.joint == k) {
          return true;
        }
      }
      return false;
    };
    if (!has(Kind::dq)) {
      fail(path, 1, "dq" + std::to_string(j), "missing required velocity column");
    }
    if (h.has_current && !has(Kind::current)) {
      fail(path, 1, "i" + std::to_string(j), "current given for some joints but not this one");
    }
    if (h.has_tau_m && !has(Kind::tau_m)) {
      fail(path, 1, "tau_m" + std::to_string(j), "motor torque given for some joints but not this one");
    }
    if (h.has_tau_j && !has(Kind::tau_j)) {
      fail(path, 1, "tau_j" + std::to_string(j), "joint torque given for some joints but not this one");
    }
    // Without this, a recording with tau_ext1 but not tau_ext2 had an empty tau_ext column
    // for joint 2 beside full ones, and regularize read past its end (found by fuzzing).
    if (h.has_tau_ext && !has(Kind::tau_ext)) {
      fail(path, 1, "tau_ext" + std::to_string(j), "external torque given for some joints but not this one");
    }
    if (!h.has_current && !h.has_tau_m && !h.has_tau_j) {
      fail(path, 1, "i" + std::to_string(j) + "/tau_m" + std::to_string(j) + "/tau_j" + std::to_string(j),
           "need motor current i<j>, motor torque tau_m<j> or joint torque tau_j<j>");
    }
  }
}

/// One parsed value into its column's signal (time strictly increasing, a collision column
/// a link number).
void store(const std::string& path, std::size_t line_no, const Column& col, const std::string& field, double v,
           Recording& rec) {
  switch (col.kind) {
    case Kind::time:
      if (!rec.t.empty() && !(v > rec.t.back())) {
        fail(path, line_no, col.name, "time " + quote(trim(field)) + " is not after the previous sample");
      }
      rec.t.push_back(v);
      break;
    case Kind::q: rec.q[col.joint].push_back(v); break;
    case Kind::dq: rec.dq[col.joint].push_back(v); break;
    case Kind::current: rec.current[col.joint].push_back(v); break;
    case Kind::tau_m: rec.tau_m[col.joint].push_back(v); break;
    case Kind::tau_j: rec.tau_j[col.joint].push_back(v); break;
    case Kind::tau_ext: rec.tau_ext[col.joint].push_back(v); break;
    case Kind::collision:
      if (v < 0.0 || v > 1e6 || v != std::floor(v)) {
        fail(path, line_no, col.name, quote(trim(field)) + " is not a link number (0 = no contact)");
      }
      rec.collision.push_back(static_cast<int>(v));
      break;
    case Kind::extra: rec.extra[col.name].push_back(v); break;
  }
}

/// The data rows after the header into rec; returns the last line's number.
std::size_t read_rows(std::ifstream& in, const std::string& path, const std::vector<Column>& cols, Recording& rec) {
  std::string line;
  std::size_t line_no = 1;
  std::string previous_row;
  std::set<std::size_t> text_columns;  ///< extra columns found to hold text
  while (std::getline(in, line)) {
    ++line_no;
    if (trim(line).empty() || trim(line) == "\r") {
      continue;
    }
    if (!line.empty() && line.back() == '\r') {
      line.pop_back();
    }
    // A row repeated character for character, time stamp included, is a logger writing
    // the same sample twice: not an error, and not a second sample.
    if (line == previous_row) {
      ++rec.duplicate_rows_dropped;
      continue;
    }
    previous_row = line;
    const auto fields = split_commas(line);
    if (fields.size() != cols.size()) {
      fail(path, line_no, "", "expected " + std::to_string(cols.size()) + " fields, found " +
                                  std::to_string(fields.size()));
    }
    for (std::size_t c = 0; c < cols.size(); ++c) {
      const Column& col = cols[c];
      double v = 0.0;
      if (col.kind == Kind::extra && text_columns.count(c) != 0U) continue;
      if (!parse_double(fields[c], v)) {
        if (col.kind == Kind::extra) {
          // An extra column is the user's (a label, a phase name): kept as a signal while it
          // is numbers; text makes it a text column, not read, and a note says where.
          text_columns.insert(c);
          rec.extra.erase(col.name);
          rec.notes.push_back(path + " line " + std::to_string(line_no) + ", column '" + col.name + "': " +
                              quote(trim(fields[c])) + " is text: the extra column is not read as a signal");
          continue;
        }
        fail(path, line_no, col.name, quote(trim(fields[c])) + " is not a finite number (column " +
                                          std::to_string(c + 1) + ")");
      }
      store(path, line_no, col, fields[c], v, rec);
    }
  }
  return line_no;
}
}  // namespace

Recording read_recording(const std::string& path, const ReadOptions& options) {
  std::ifstream in(path);
  if (!in) {
    throw FormatError(path + ": cannot open recording");
  }
  std::string line;
  if (!std::getline(in, line)) {
    fail(path, 1, "", "empty file: expected a header line");
  }
  const auto header = split_commas(line);
  const std::set<int> q_ids = position_joints(path, line, header);
  Recording rec;
  rec.joint_ids.assign(q_ids.begin(), q_ids.end());
  std::map<int, std::size_t> joint_index;
  for (std::size_t k = 0; k < rec.joint_ids.size(); ++k) {
    joint_index[rec.joint_ids[k]] = k;
  }
  const Header h = classify_columns(path, header, options, rec, joint_index);
  check_joint_columns(path, h, rec, joint_index);
  const std::size_t n = rec.joint_ids.size();
  rec.q.assign(n, {});
  rec.dq.assign(n, {});
  if (h.has_current) rec.current.assign(n, {});
  if (h.has_tau_m) rec.tau_m.assign(n, {});
  if (h.has_tau_j) rec.tau_j.assign(n, {});
  if (h.has_tau_ext) rec.tau_ext.assign(n, {});

  const std::size_t line_no = read_rows(in, path, h.cols, rec);
  if (rec.t.empty()) {
    fail(path, line_no, "", "no data rows after the header");
  }
  resolve_torque(rec, path, options.torque);
  check_time_unit(rec, path, options.time_column);
  const std::filesystem::path p(path);
  rec.meta = read_meta(side_file_path(path), rec.notes);
  for (const auto& note : rec.notes) std::fprintf(stderr, "note: %s\n", note.c_str());
  return rec;
}

std::string side_file_path(const std::string& csv_path) {
  const std::filesystem::path p(csv_path);
  return (p.parent_path() / (p.stem().string() + ".json")).string();
}

SideFile classify_side_file(const std::string& json_path, std::string* why) {
  bool found = false;
  const std::string text = read_text_file(json_path, found);
  if (!found) return std::filesystem::exists(json_path) ? SideFile::foreign : SideFile::absent;
  return classify(json_path, text, why);
}

void check_side_file_writable(const std::string& csv_path) {
  const std::string side = side_file_path(csv_path);
  std::string why;
  if (classify_side_file(side, &why) != SideFile::foreign) return;
  throw FormatError(side + ": the recording's side file would overwrite a file that is not jointguard's (" + why +
                    "): not overwritten; move it away or write the recording under another name");
}

namespace {
void check_shapes(const Recording& rec) {
  const std::size_t n = rec.joints();
  const std::size_t m = rec.samples();
  auto check = [&](const std::vector<std::vector<double>>& sig, const char* name) {
    if (!sig.empty() && (sig.size() != n || std::any_of(sig.begin(), sig.end(), [&](const auto& v) {
                           return v.size() != m;
                         }))) {
      throw std::invalid_argument(std::string("write_recording: signal '") + name + "' has the wrong shape");
    }
  };
  check(rec.q, "q");
  check(rec.dq, "dq");
  check(rec.current, "i");
  check(rec.tau_m, "tau_m");
  check(rec.tau_j, "tau_j");
  check(rec.tau_ext, "tau_ext");
  if (rec.q.empty() || rec.dq.empty() || (rec.current.empty() && rec.tau_m.empty() && rec.tau_j.empty())) {
    throw std::invalid_argument("write_recording: q, dq and one of i/tau_m/tau_j are required");
  }
}

void write_header(std::ostream& out, const Recording& rec) {
  out << "t";
  auto head = [&](const std::vector<std::vector<double>>& sig, const char* prefix) {
    if (!sig.empty()) {
      for (const int j : rec.joint_ids) out << ',' << prefix << j;
    }
  };
  head(rec.q, "q");
  head(rec.dq, "dq");
  head(rec.current, "i");
  head(rec.tau_m, "tau_m");
  head(rec.tau_j, "tau_j");
  head(rec.tau_ext, "tau_ext");
  if (!rec.collision.empty()) out << ",collision";
  for (const auto& [name, values] : rec.extra) out << ',' << name;
  out << '\n';
}

void write_rows(std::ostream& out, const Recording& rec) {
  // Shortest representation that reads back to the same double: exact round trip. The
  // rows are formatted into a block of memory and written a block at a time (a stream
  // write per number cost as much as the formatting).
  std::vector<char> block(std::size_t{1} << 16);
  std::size_t used = 0;
  constexpr std::size_t kNumberMax = 32;  // the longest double to_chars writes is 24 characters
  auto flush = [&] {
    out.write(block.data(), static_cast<std::streamsize>(used));
    used = 0;
  };
  auto put_plain = [&](double v) {
    if (block.size() - used < kNumberMax + 1) flush();
    used = static_cast<std::size_t>(std::to_chars(block.data() + used, block.data() + block.size(), v).ptr - block.data());
  };
  auto put_char = [&](char c) {
    if (used == block.size()) flush();
    block[used++] = c;
  };
  for (std::size_t k = 0; k < rec.samples(); ++k) {
    put_plain(rec.t[k]);
    for (const auto* sig : {&rec.q, &rec.dq, &rec.current, &rec.tau_m, &rec.tau_j, &rec.tau_ext}) {
      for (const auto& v : *sig) {
        put_char(',');
        put_plain(v[k]);
      }
    }
    if (!rec.collision.empty()) {
      put_char(',');
      if (block.size() - used < kNumberMax) flush();
      used = static_cast<std::size_t>(std::to_chars(block.data() + used, block.data() + block.size(), rec.collision[k]).ptr -
                                      block.data());
    }
    for (const auto& [name, values] : rec.extra) {
      put_char(',');
      put_plain(values.at(k));
    }
    put_char('\n');
  }
  flush();
}
}  // namespace

void write_recording(const std::string& path, const Recording& rec) {
  check_shapes(rec);
  const std::filesystem::path target(path);
  if (side_file_path(path) == path) {
    throw FormatError(path + ": a recording is a CSV file; its side file <name>.json would be the same file");
  }
  if (target.has_parent_path()) {
    std::filesystem::create_directories(target.parent_path());
  }
  check_side_file_writable(path);  // before the work of writing: refused, nothing written
  TempFile csv(target);
  {
    std::ofstream out(csv.path(), std::ios::binary | std::ios::trunc);
    if (!out) throw FormatError(path + ": cannot write recording");
    write_header(out, rec);
    write_rows(out, rec);
    if (!out.flush()) throw FormatError(path + ": write failed");
  }
  nlohmann::json meta{{"format", kSideFileFormat},
                      {"model", rec.meta.model},
                      {"sample_time", rec.meta.sample_time},
                      {"scenario", rec.meta.scenario}};
  if (rec.meta.seed) meta["seed"] = *rec.meta.seed;
  if (!rec.meta.identity_json.empty()) meta["identity"] = nlohmann::json::parse(rec.meta.identity_json);
  TempFile json(side_file_path(path));
  {
    std::ofstream jout(json.path(), std::ios::binary | std::ios::trunc);
    // Text that is not UTF-8 replaced (U+FFFD), never an exception after the CSV is written.
    jout << meta.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) << '\n';
    if (!jout.flush()) throw FormatError(json.target().string() + ": write failed");
  }
  // Both renames under the folder's lock: another writer of the same recording renames its
  // pair before or after, so the CSV and its side file always come from one run. The side
  // file is checked again: another program may have put its file there meanwhile.
  const FolderLock lock(target.has_parent_path() ? target.parent_path() : std::filesystem::path("."));
  check_side_file_writable(path);
  json.commit();
  csv.commit();
}

}  // namespace jg::io
