// The shipped DBC describes the frames the code sends: every message kind encoded by the
// protocol functions, written as a candump -L log, read back and decoded with the DBC gives
// the encoded values; bad captures and DBC lines are refused with file:line.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>

#include "can/dbc.hpp"
#include "jointguard/protocol/frames.hpp"

namespace {
using namespace jg;

std::string dbc_path() { return std::string(JG_SOURCE_DIR) + "/docs/can/jointguard.dbc"; }

std::string candump_line(const hal::CanFrame& f) {
  char id[16];
  std::snprintf(id, sizeof id, "%03X", f.id);
  std::string s = "(1700000000.000100) vcan0 " + std::string(id) + (f.fd ? "##1" : "#");
  for (unsigned i = 0; i < f.length; ++i) {
    char b[4];
    std::snprintf(b, sizeof b, "%02X", f.data[i]);
    s += b;
  }
  return s;
}

double signal(const can::Dbc& dbc, std::uint32_t id, const std::string& name, const hal::CanFrame& f) {
  for (const auto& s : dbc.messages.at(id).signals) {
    if (s.name == name) return can::decode_signal(s, f.data, f.length);
  }
  ADD_FAILURE() << "no signal " << name;
  return 0.0;
}

TEST(Dbc, DescribesEveryFrameTheProtocolSends) {
  const can::Dbc dbc = can::read_dbc(dbc_path());
  std::vector<hal::CanFrame> sent;
  hal::CanFrame f{};
  f.fd = true;
  f.id = protocol::kSyncId;
  f.length = protocol::encode_sync(70000U, f.data);
  sent.push_back(f);
  f.id = protocol::frame_id(protocol::MessageKind::sensor, 2);
  f.length = protocol::encode_sensor(protocol::SensorMessage<q16>{q16::from_double(-1.25), q16::from_double(0.5), q16::from_double(12.0), true}, 7, f.data);
  sent.push_back(f);
  f.id = protocol::frame_id(protocol::MessageKind::status, 3);
  f.length = protocol::encode_status(protocol::StatusMessage<q16>{q16::from_double(-3.5), protocol::kStatusCollision | protocol::kStatusReady, 4}, 9, f.data);
  sent.push_back(f);
  f.id = protocol::frame_id(protocol::MessageKind::collision_event, 3);
  sent.push_back(f);
  OutwardMessage<q16> o{};
  o.gravity.z = q16::from_double(-9.81);
  f.id = protocol::frame_id(protocol::MessageKind::outward, 1);
  f.length = protocol::encode_outward(o, 200, f.data);
  sent.push_back(f);
  InwardMessage<q16> in{};
  in.mass = q16::from_double(4.5);
  in.angular_momentum.y = q16::from_double(-0.75);
  f.id = protocol::frame_id(protocol::MessageKind::inward, 2);
  f.length = protocol::encode_inward(in, 201, f.data);
  sent.push_back(f);
  const std::string log = ::testing::TempDir() + "/jg_capture.log";
  {
    std::ofstream out(log);
    for (const auto& s : sent) out << candump_line(s) << '\n';
  }
  const auto got = can::read_candump_log(log);
  ASSERT_EQ(got.size(), sent.size());
  for (const auto& c : got) {
    ASSERT_EQ(dbc.messages.count(c.frame.id), 1U) << c.frame.id;
    EXPECT_EQ(dbc.messages.at(c.frame.id).length, c.frame.length) << dbc.messages.at(c.frame.id).name;
    EXPECT_EQ(dbc.messages.at(c.frame.id).fd, c.frame.fd);
  }
  EXPECT_EQ(signal(dbc, 0x010, "cycle", got[0].frame), 70000.0);
  EXPECT_EQ(signal(dbc, 0x010, "seq", got[0].frame), 70000 % 256);
  EXPECT_DOUBLE_EQ(signal(dbc, 0x062, "q", got[1].frame), -1.25);
  EXPECT_DOUBLE_EQ(signal(dbc, 0x062, "tau_m", got[1].frame), 12.0);
  EXPECT_EQ(signal(dbc, 0x062, "holding", got[1].frame), 1.0);
  EXPECT_EQ(signal(dbc, 0x062, "flags_copy", got[1].frame), 1.0);
  EXPECT_EQ(signal(dbc, 0x062, "crc", got[1].frame), got[1].frame.data[13]);
  EXPECT_DOUBLE_EQ(signal(dbc, 0x053, "external_torque", got[2].frame), -3.5);
  EXPECT_EQ(signal(dbc, 0x053, "collision", got[2].frame), 1.0);
  EXPECT_EQ(signal(dbc, 0x053, "comm_fault", got[2].frame), 0.0);
  EXPECT_EQ(signal(dbc, 0x053, "ready", got[2].frame), 1.0);
  EXPECT_EQ(signal(dbc, 0x053, "rejected", got[2].frame), 4.0);
  EXPECT_EQ(signal(dbc, 0x003, "crc", got[3].frame), got[3].frame.data[7]);
  EXPECT_NEAR(signal(dbc, 0x021, "g_z", got[4].frame), -9.81, 1.0 / 65536.0);
  EXPECT_DOUBLE_EQ(signal(dbc, 0x032, "mass", got[5].frame), 4.5);
  EXPECT_DOUBLE_EQ(signal(dbc, 0x032, "n_y", got[5].frame), -0.75);
  EXPECT_EQ(signal(dbc, 0x032, "seq", got[5].frame), 201.0);
}

TEST(Dbc, BadCaptureLinesAreRefusedWithFileAndLine) {
  const std::string log = ::testing::TempDir() + "/jg_bad_capture.log";
  // The last five (issue 14): a time stamp that is not a number, an 11-bit identifier
  // beyond 0x7FF, a 29-bit one beyond 0x1FFFFFFF, CAN FD without its flags nibble.
  for (const char* bad : {"vcan0 123#00", "(1.0) vcan0 12G#00", "(1.0) vcan0 123#0", "(1.0) vcan0 123", "(1.0) vcan0 123#R",
                          "(abc) vcan0 123#00", "(nan) vcan0 123#00", "(1.0) vcan0 FFF#00", "(1.0) vcan0 FFFFFFFF#00",
                          "(1.0) vcan0 123##"}) {
    {
      std::ofstream out(log);
      out << "(1.0) vcan0 010##1" << std::string(16, '0') << '\n' << bad << '\n';
    }
    try {
      (void)can::read_candump_log(log);
      ADD_FAILURE() << "accepted: " << bad;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(log + ":2:"), std::string::npos) << e.what();
    }
  }
}

// Signal definitions the reader used to accept (issue 14, fuzzing): a start bit near 2^32
// wrapped the end-of-signal sum past the check, Motorola signals were not checked at all,
// factors and offsets that are not numbers were read as 0.
TEST(Dbc, BadSignalDefinitionsAreRefusedWithFileAndLine) {
  const std::string path = ::testing::TempDir() + "/jg_bad_signal.dbc";
  for (const char* bad : {" SG_ x : 4294967295|2@1+ (1,0) [0|1] \"\" M", " SG_ x : 7|16@0+ (1,0) [0|1] \"\" M",
                          " SG_ x : 60|8@0+ (1,0) [0|1] \"\" M", " SG_ x : 0|8@1+ (abc,0) [0|1] \"\" M",
                          " SG_ x : 0|8@1+ (1,nan) [0|1] \"\" M", " SG_ x : 0|8@1+ (1e999,0) [0|1] \"\" M"}) {
    {
      std::ofstream out(path);
      out << "BO_ 16 CYCLE_SYNC: 1 MASTER\n" << bad << '\n';
    }
    try {
      (void)can::read_dbc(path);
      ADD_FAILURE() << "accepted: " << bad;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(path + ":2:"), std::string::npos) << e.what();
    }
  }
  {
    std::ofstream out(path);
    out << "BO_ 16 CYCLE_SYNC: 2 MASTER\n SG_ x : 7|16@0+ (0.5,-3) [0|1] \"\" M\n";
  }
  const can::Dbc dbc = can::read_dbc(path);
  const std::uint8_t data[2] = {0x01, 0x02};  // Motorola: 0x0102 = 258
  EXPECT_DOUBLE_EQ(can::decode_signal(dbc.messages.at(16).signals.at(0), data, 2), 258 * 0.5 - 3);
}

// The reader's hand-written scanner takes the grammar the std::regex reader took (checked
// against it on 3 million mutated lines when it replaced it): spacing variants read the
// same, truncated or malformed definitions are refused naming file and line.
TEST(Dbc, ScannerReadsSpacingVariantsAndRefusesMalformedLines) {
  const std::string path = ::testing::TempDir() + "/jg_scanner.dbc";
  {
    std::ofstream out(path);
    out << "BO_\t16  CYCLE_SYNC :2\tMASTER \n"
           "SG_\tx:0|8@1-(0.5,-3)[a|b]\"N.m\" A,B\n"
           "  SG_ y : 15|8@0+ ( 1,2) [0|1] \"\"\n"
           "BA_ \"VFrameFormat\"\tBO_ 16 14 ; \n"
           "SG_MUL_VAL_ 16 y x 0-1;\n";  // another keyword, not a signal: ignored
  }
  const can::Dbc dbc = can::read_dbc(path);
  const can::DbcMessage& m = dbc.messages.at(16);
  EXPECT_EQ(m.name, "CYCLE_SYNC");
  EXPECT_EQ(m.length, 2U);
  EXPECT_EQ(m.sender, "MASTER");
  EXPECT_TRUE(m.fd);
  ASSERT_EQ(m.signals.size(), 2U);
  EXPECT_EQ(m.signals[0].name, "x");
  EXPECT_TRUE(m.signals[0].little_endian);
  EXPECT_TRUE(m.signals[0].is_signed);
  EXPECT_EQ(m.signals[0].unit, "N.m");
  EXPECT_FALSE(m.signals[1].little_endian);
  const std::uint8_t data[2] = {0xFE, 0x05};  // x = -2 (signed), y = 5
  EXPECT_DOUBLE_EQ(can::decode_signal(m.signals[0], data, 2), -2 * 0.5 - 3);
  // Malformed: no closing quote, parenthesis or bracket, a bad byte order or sign, an empty
  // factor or start bit, no colon, a carriage return inside the line.
  for (const char* bad : {" SG_ x : 0|8@1+ (1,0) [0|1] \"unit M", " SG_ x : 0|8@1+ (1,0 [0|1] \"\" M", " SG_ x : 0|8@2+ (1,0) [0|1] \"\" M",
                          " SG_ x : 0|8@1* (1,0) [0|1] \"\" M", " SG_ x : 0|8@1+ (,0) [0|1] \"\" M", " SG_ x 0|8@1+ (1,0) [0|1] \"\" M",
                          " SG_ x : 0|8@1+ (1,0) [0|1 \"\" M", " SG_ x : |8@1+ (1,0) [0|1] \"\" M", " SG_ x : 0|8@1+ (1,0) [0|1] \"\" M\r M"}) {
    {
      std::ofstream out(path);
      out << "BO_ 16 CYCLE_SYNC: 1 MASTER\n" << bad << '\n';
    }
    try {
      (void)can::read_dbc(path);
      ADD_FAILURE() << "accepted: " << bad;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(path + ":2: cannot read the signal definition"), std::string::npos) << e.what();
    }
  }
  for (const char* bad : {"BO_ 16 CYCLE_SYNC 1 MASTER", "BO_ 16 CYCLE_SYNC: 1", "BO_ x CYCLE_SYNC: 1 MASTER", "BO_ 16 CYCLE-SYNC: 1 M"}) {
    {
      std::ofstream out(path);
      out << bad << '\n';
    }
    try {
      (void)can::read_dbc(path);
      ADD_FAILURE() << "accepted: " << bad;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(path + ":1: cannot read the message definition"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
