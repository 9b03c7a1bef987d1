// A reader for the DBC subset the project's bus description uses (messages, little- and
// big-endian signals with factor and offset, the VFrameFormat attribute) and for candump's
// log format (`candump -L`), so that a capture of the joint bus can be decoded and checked
// against docs/can/jointguard.dbc without tools outside Debian. Errors name file and line.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "jointguard/hal/can.hpp"

namespace jg::can {

struct DbcSignal {
  std::string name, unit;
  unsigned start = 0, size = 0;
  bool little_endian = true, is_signed = false;
  double factor = 1.0, offset = 0.0;
};

struct DbcMessage {
  std::uint32_t id = 0;
  std::string name, sender;
  unsigned length = 0;
  bool fd = false;
  std::vector<DbcSignal> signals;
};

struct Dbc {
  std::map<std::uint32_t, DbcMessage> messages;
};

/// Throws std::runtime_error("FILE:LINE: ...") on what it cannot read.
Dbc read_dbc(const std::string& path);

/// Physical value of a signal in a payload.
double decode_signal(const DbcSignal& s, const std::uint8_t* data, unsigned length);

struct CapturedFrame {
  double t = 0.0;
  std::string interface;
  hal::CanFrame frame;
};

/// candump -L lines: "(1700000000.123456) vcan0 123#11223344" (classic) and
/// "(…) vcan0 123##1<hex>" (CAN FD, flags nibble). Throws naming FILE:LINE.
std::vector<CapturedFrame> read_candump_log(const std::string& path);

}  // namespace jg::can
