#include "can/fault_spec.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

#include "jointguard/protocol/frames.hpp"

namespace jg::hil {
namespace {

struct KindName {
  const char* name;
  FaultKind kind;
};
constexpr KindName kKinds[] = {
    {"drop", FaultKind::drop},           {"late", FaultKind::late},       {"corrupt", FaultKind::corrupt},
    {"duplicate", FaultKind::duplicate}, {"babble", FaultKind::babble},   {"bus-off", FaultKind::bus_off},
    {"restart", FaultKind::restart},     {"link-down", FaultKind::link_down}, {"nan-sensor", FaultKind::nan_sensor},
};

[[noreturn]] void fail(const std::string& text, const std::string& why) {
  throw std::invalid_argument("--fault '" + text + "': " + why + " (syntax: KIND[:TARGET]@START[:DURATION], e.g. drop:2@0.5:0.2)");
}

/// A time in seconds: a plain finite decimal number >= 0, nothing after it.
double parse_time(const std::string& text, const std::string& field, const std::string& what) {
  if (field.empty()) fail(text, what + " is empty");
  const char* begin = field.c_str();
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(begin, &end);
  if (end == begin || *end != '\0' || errno == ERANGE || !std::isfinite(v) || field.find_first_of("xXpP") != std::string::npos) {
    fail(text, what + " '" + field + "' is not a number of seconds");
  }
  if (v < 0.0) fail(text, what + " '" + field + "' is negative");
  return v;
}

bool takes_frame_target(FaultKind k) {
  return k == FaultKind::drop || k == FaultKind::late || k == FaultKind::corrupt || k == FaultKind::duplicate;
}

}  // namespace

const char* to_string(FaultKind kind) {
  for (const auto& k : kKinds) {
    if (k.kind == kind) return k.name;
  }
  return "?";
}

FaultSpec parse_fault(const std::string& text) {
  FaultSpec f;
  f.text = text;
  const std::size_t at = text.find('@');
  if (at == std::string::npos) fail(text, "no '@START' (when the fault starts, in seconds of plant time)");
  if (text.find('@', at + 1) != std::string::npos) fail(text, "more than one '@'");
  const std::string head = text.substr(0, at), when = text.substr(at + 1);
  const std::size_t colon = head.find(':');
  const std::string kind = head.substr(0, colon);
  bool known = false;
  for (const auto& k : kKinds) {
    if (kind == k.name) {
      f.kind = k.kind;
      known = true;
    }
  }
  if (!known) {
    fail(text, "unknown kind '" + kind + "' (one of drop, late, corrupt, duplicate, babble, bus-off, restart, link-down, nan-sensor)");
  }
  if (colon != std::string::npos) {
    const std::string target = head.substr(colon + 1);
    if (target.empty()) fail(text, "empty target after ':'");
    const bool hex = target.size() > 2 && target[0] == '0' && (target[1] == 'x' || target[1] == 'X');
    const std::string digits = hex ? target.substr(2) : target;
    const char* allowed = hex ? "0123456789abcdefABCDEF" : "0123456789";
    if (digits.empty() || digits.size() > 8 || digits.find_first_not_of(allowed) != std::string::npos) {
      fail(text, "target '" + target + "' is neither a joint number (1..7) nor an identifier (0x000..0x7FF)");
    }
    const unsigned long v = std::strtoul(digits.c_str(), nullptr, hex ? 16 : 10);
    if (hex) {
      if (v > 0x7FFUL) fail(text, "identifier " + target + " is not an 11-bit identifier (0x000..0x7FF)");
      if (!takes_frame_target(f.kind) && f.kind != FaultKind::babble) fail(text, std::string(to_string(f.kind)) + " takes no identifier");
      f.id = static_cast<std::uint32_t>(v);
      f.has_id = true;
    } else {
      if (v < 1UL || v > 7UL) fail(text, "joint " + target + " is not a joint number (1..7)");
      if (f.kind == FaultKind::babble) fail(text, "babble takes the babbled identifier as target (e.g. babble:0x001), not a joint");
      if (f.kind == FaultKind::link_down) fail(text, "link-down silences the whole bus: it takes no target");
      f.joint = static_cast<int>(v);
    }
  }
  if ((f.kind == FaultKind::bus_off || f.kind == FaultKind::restart) && f.joint == 0) {
    fail(text, std::string(to_string(f.kind)) + " needs the drive as target (e.g. " + to_string(f.kind) + ":2@0.5:0.3)");
  }
  if (f.kind == FaultKind::babble && !f.has_id) f.id = kDefaultBabbleId;
  const std::size_t colon2 = when.find(':');
  f.start_s = parse_time(text, when.substr(0, colon2), "start");
  if (colon2 != std::string::npos) {
    f.duration_s = parse_time(text, when.substr(colon2 + 1), "duration");
    if (f.duration_s <= 0.0 && f.kind != FaultKind::restart) fail(text, "duration must be > 0 (omit it: until the end of the run)");
  } else if (f.kind == FaultKind::restart) {
    f.duration_s = 0.0;  // power-cycled at once: back from the next sync
  }
  return f;
}

void check_faults(const std::vector<FaultSpec>& faults, std::size_t joints, double duration_s) {
  for (const FaultSpec& f : faults) {
    if (f.joint > 0 && static_cast<std::size_t>(f.joint) > joints) {
      throw std::invalid_argument("--fault '" + f.text + "': joint " + std::to_string(f.joint) + " does not exist (the arm has joints 1.." +
                                  std::to_string(joints) + ")");
    }
    if (f.start_s >= duration_s) {
      throw std::invalid_argument("--fault '" + f.text + "': starts at " + std::to_string(f.start_s) + " s, after the run's end (" +
                                  std::to_string(duration_s) + " s)");
    }
  }
}

std::vector<std::uint32_t> drive_identifiers(int joint) {
  const auto j = static_cast<std::uint8_t>(joint);
  return {protocol::frame_id(protocol::MessageKind::collision_event, j), protocol::frame_id(protocol::MessageKind::outward, j),
          protocol::frame_id(protocol::MessageKind::inward, j), protocol::frame_id(protocol::MessageKind::status, j)};
}

const char* fault_syntax_help() {
  return "Inject a bus fault mid-run (repeatable): KIND[:TARGET]@START[:DURATION], times in s of plant time; no DURATION: until "
         "the end.\n"
         "KIND: drop | late (+10 ms) | corrupt (a byte flipped) | duplicate  [TARGET: joint J = the frames drive J sends, or an "
         "identifier 0xNNN; none: every frame];\n"
         "babble[:0xID] (a node sending ID, default 0x001, whenever the bus is idle); bus-off:J; restart:J (drive J off for "
         "DURATION, default 0, then rebooted); link-down (the whole bus silent); nan-sensor[:J] (NaN samples to drive J, default "
         "all).\n"
         "Example: --fault drop:2@0.5:0.2 --fault restart:2@1.0:0.3";
}

}  // namespace jg::hil
