// Recording CSV: round trip, extra/missing optional columns, and errors that name
// file, line and field.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "io/recording.hpp"

namespace {
namespace fs = std::filesystem;
using jg::io::FormatError;

class RecordingTest : public ::testing::Test {
 protected:
  fs::path dir = fs::temp_directory_path() / ("jg_rec_" + std::to_string(::getpid()) + "_" +
                                              ::testing::UnitTest::GetInstance()->current_test_info()->name());
  void SetUp() override { fs::create_directories(dir); }
  void TearDown() override { fs::remove_all(dir); }
  std::string write(const std::string& name, const std::string& text) {
    const auto p = dir / name;
    std::ofstream(p) << text;
    return p.string();
  }
  std::string error_of(const std::string& path, const jg::io::ReadOptions& o = {}) {
    try {
      (void)jg::io::read_recording(path, o);
    } catch (const FormatError& e) {
      return e.what();
    }
    return "no error";
  }
};

TEST_F(RecordingTest, RoundTripIsExactAndKeepsMetadata) {
  jg::io::Recording rec;
  rec.resize(2, 3, true, true, true, true);
  for (std::size_t k = 0; k < 3; ++k) {
    rec.t[k] = 0.001 * static_cast<double>(k);
    for (std::size_t j = 0; j < 2; ++j) {
      rec.q[j][k] = 0.1 * static_cast<double>(j) + 1e-7 * static_cast<double>(k);
      rec.dq[j][k] = -0.5 + static_cast<double>(k);
      rec.current[j][k] = 1.25;
      rec.tau_m[j][k] = 12.5;
      rec.tau_ext[j][k] = static_cast<double>(k == 2) * 3.0;
    }
  }
  rec.collision = {0, 0, 2};
  rec.extra["temperature"] = {20.0, 20.5, 21.0};
  rec.meta.model = "ref3";
  rec.meta.sample_time = 0.001;
  rec.meta.seed = 42;
  const std::string path = (dir / "r.csv").string();
  jg::io::write_recording(path, rec);
  const auto back = jg::io::read_recording(path);
  ASSERT_EQ(back.joints(), 2U);
  ASSERT_EQ(back.samples(), 3U);
  EXPECT_EQ(back.q[1][2], rec.q[1][2]);
  EXPECT_EQ(back.collision[2], 2);
  EXPECT_EQ(back.extra.at("temperature")[1], 20.5);
  EXPECT_EQ(back.meta.model, "ref3");
  EXPECT_EQ(back.meta.seed.value_or(0), 42U);
  EXPECT_FALSE(fs::exists(path + ".tmp"));
}

TEST_F(RecordingTest, AcceptsExtraColumnsAndMissingOptionalOnes) {
  const auto p = write("a.csv", "t,q1,dq1,i1,note\n0,0.1,0.2,1.5,7\n0.001,0.1,0.2,1.5,8\n");
  const auto r = jg::io::read_recording(p);
  EXPECT_TRUE(r.tau_ext.empty());
  EXPECT_TRUE(r.tau_m.empty());
  EXPECT_TRUE(r.collision.empty());
  EXPECT_EQ(r.current[0][1], 1.5);
  EXPECT_EQ(r.extra.at("note")[1], 8.0);
}

TEST_F(RecordingTest, RealDataLayoutWithTimeColumnAndTorquePattern) {
  const auto p = write("franka.csv",
                       "time,q2,dq2,ddq2,q2_tau_J_compensate,LuGre\n0,-0.78,0.001,0,-0.07,0.0\n0.003,-0.78,-0.0004,0,-0.02,0.0\n");
  jg::io::ReadOptions o;
  o.time_column = "time";
  o.torque_column_pattern = "q{j}_tau_J_compensate";
  const auto r = jg::io::read_recording(p, o);
  ASSERT_EQ(r.joint_ids, std::vector<int>{2});
  EXPECT_DOUBLE_EQ(r.tau_m[0][1], -0.02);
  EXPECT_TRUE(r.extra.count("ddq2") == 1U);
}

TEST_F(RecordingTest, ErrorsNameFileLineAndField) {
  auto p = write("nan.csv", "t,q1,dq1,i1\n0,0,0,0\n0.001,0,nan,0\n");
  EXPECT_NE(error_of(p).find("nan.csv:3: field 'dq1': 'nan' is not a finite number (column 3)"),
            std::string::npos) << error_of(p);
  p = write("time.csv", "t,q1,dq1,i1\n0,0,0,0\n0,0,0,0\n");
  EXPECT_NE(error_of(p).find("time.csv:3: field 't'"), std::string::npos) << error_of(p);
  p = write("missing.csv", "t,q1,i1\n0,0,0\n");
  EXPECT_NE(error_of(p).find("missing.csv:1: field 'dq1': missing required velocity column"), std::string::npos)
      << error_of(p);
  p = write("count.csv", "t,q1,dq1,i1\n0,0,0\n");
  EXPECT_NE(error_of(p).find("count.csv:2: expected 4 fields, found 3"), std::string::npos) << error_of(p);
  p = write("torque.csv", "t,q1,dq1\n0,0,0\n");
  EXPECT_NE(error_of(p).find("need motor current"), std::string::npos) << error_of(p);
  p = write("unit.csv", "t,q1,dq1,i1\n0,0.1rad,0,0\n");
  EXPECT_NE(error_of(p).find("unit.csv:2: field 'q1': '0.1rad'"), std::string::npos) << error_of(p);
  p = write("coll.csv", "t,q1,dq1,i1,collision\n0,0,0,0,1.5\n");
  EXPECT_NE(error_of(p).find("field 'collision'"), std::string::npos) << error_of(p);
  p = write("empty.csv", "t,q1,dq1,i1\n");
  EXPECT_NE(error_of(p).find("no data rows"), std::string::npos) << error_of(p);
  EXPECT_NE(error_of((dir / "absent.csv").string()).find("cannot open"), std::string::npos);
}
}  // namespace
