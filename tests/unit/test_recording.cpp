// Recording CSV: round trip, extra/missing optional columns, and errors that name
// file, line and field.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <thread>

#include "io/atomic_write.hpp"
#include "io/recording.hpp"
#include "io/regularize.hpp"
#include "io/trace_csv.hpp"
#include "robot/torque_kind.hpp"

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
  // A text extra column (a phase label) is the user's: the recording is read, the column
  // is not a signal, and a note names the line and column where the text begins.
  const auto t = write("text.csv", "t,q1,dq1,i1,phase,note\n0,0.1,0.2,1.5,2,7\n0.001,0.1,0.2,1.5,lift,8\n");
  const auto rt = jg::io::read_recording(t);
  EXPECT_EQ(rt.extra.count("phase"), 0U);
  EXPECT_EQ(rt.extra.at("note").size(), 2U);
  ASSERT_FALSE(rt.notes.empty());
  EXPECT_NE(rt.notes.back().find("text.csv line 3, column 'phase': 'lift' is text"), std::string::npos) << rt.notes.back();
}

TEST_F(RecordingTest, OtherCsvDialectsAreNamed) {
  auto p = write("semi.csv", "t;q1;dq1;i1\n0;0;0;0\n");
  EXPECT_NE(error_of(p).find("semi.csv:1: the header is separated by ';'"), std::string::npos) << error_of(p);
  p = write("tab.csv", "t\tq1\tdq1\ti1\n0\t0\t0\t0\n");
  EXPECT_NE(error_of(p).find("tab.csv:1: the header is separated by tabs"), std::string::npos) << error_of(p);
  p = write("quoted.csv", "\"t\",\"q1\",\"dq1\",\"i1\"\n0,0,0,0\n");
  EXPECT_NE(error_of(p).find("quoted.csv:1: field '\"t\"': quoted column names are not read"), std::string::npos) << error_of(p);
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

// Found by fuzzing (tests/fuzz/regressions/recording/tau_ext_one_joint*.csv): tau_ext for
// one joint of two left an empty column beside a full one and regularize read past it.
// Binary bytes in a field are not echoed; the side file's JSON errors give line and column.
TEST_F(RecordingTest, PartialGroundTruthBinaryFieldsAndBadSideFileAreRefused) {
  auto p = write("ext.csv", "t,q1,q2,dq1,dq2,i1,i2,tau_ext1\n0,0,0,0,0,0,0,0\n0.001,0,0,0,0,0,0,0\n");
  EXPECT_NE(error_of(p).find("ext.csv:1: field 'tau_ext2': external torque given for some joints but not this one"),
            std::string::npos) << error_of(p);
  p = write("bin.csv", std::string("t,q1,dq1,i1\n0,0,0,0\n0.001,0,\x01\xff,0\n"));
  EXPECT_NE(error_of(p).find("bin.csv:3: field 'dq1': '?" "?' is not a finite number"), std::string::npos) << error_of(p);
  p = write("side.csv", "t,q1,dq1,i1\n0,0,0,0\n0.001,0,0,0\n");
  // Broken JSON that names jointguard is ours and refused; another program's is ignored
  // (ForeignSideFileIsIgnoredAndNeverOverwritten).
  write("side.json", "{\"format\": \"jointguard-recording\",\n  \"model\": ref3\n}\n");
  EXPECT_NE(error_of(p).find("side.json:2:"), std::string::npos) << error_of(p);
  write("side.json", "{\"format\": \"jointguard-recording\", \"sample_time\": 1e999}\n");  // nlohmann's out_of_range.406 escaped before
  EXPECT_NE(error_of(p).find("side.json: invalid JSON: a number beyond the range of a double"), std::string::npos) << error_of(p);
  write("side.json", "{\"sample_time\": -1}\n");
  EXPECT_NE(error_of(p).find("side.json: field 'sample_time': must be >= 0"), std::string::npos) << error_of(p);
}

TEST_F(RecordingTest, ErrorsNameFileLineAndField) {
  auto p = write("nan.csv", "t,q1,dq1,i1\n0,0,0,0\n0.001,0,nan,0\n");
  EXPECT_NE(error_of(p).find("nan.csv:3: field 'dq1': 'nan' is not a finite number (column 3)"),
            std::string::npos) << error_of(p);
  p = write("time.csv", "t,q1,dq1,i1\n0,0,0,0\n0,0,1,0\n");
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

TEST_F(RecordingTest, ExactDuplicateRowsAreDroppedAndCounted) {
  const auto p = write("dup.csv", "t,q1,dq1,i1\n0,0,0,0\n0,0,0,0\n0.001,0.1,0,0\n");
  const auto r = jg::io::read_recording(p);
  EXPECT_EQ(r.samples(), 2U);
  EXPECT_EQ(r.duplicate_rows_dropped, 1U);
}

TEST_F(RecordingTest, TorqueKindFromColumnsAndFromTheUser) {
  const auto pj = write("j.csv", "t,q1,dq1,tau_j1,i1\n0,0,0,2.5,1\n0.001,0,0,2.5,1\n");
  const auto rj = jg::io::read_recording(pj);
  EXPECT_EQ(rj.torque_kind, jg::io::TorqueKind::tau_j);
  EXPECT_EQ(jg::io::torque_columns(rj)[0][1], 2.5);
  EXPECT_STREQ(jg::io::to_string(rj.torque_kind), "tau_j");
  // A torque sensor's reading logged under tau_m<j> (the Panda file): re-read as tau_j.
  const auto pm = write("m.csv", "t,q1,dq1,tau_m1\n0,0,0,3\n0.001,0,0,4\n");
  EXPECT_EQ(jg::io::read_recording(pm).torque_kind, jg::io::TorqueKind::tau_m);
  jg::io::ReadOptions o;
  o.torque = jg::io::TorqueChoice::joint;
  const auto rm = jg::io::read_recording(pm, o);
  EXPECT_EQ(rm.torque_kind, jg::io::TorqueKind::tau_j);
  EXPECT_TRUE(rm.tau_m.empty());
  EXPECT_EQ(rm.tau_j[0][1], 4.0);
  // A kind the file does not carry is refused, naming the field.
  o.torque = jg::io::TorqueChoice::current;
  EXPECT_NE(error_of(pm, o).find("m.csv:1: field 'i1'"), std::string::npos) << error_of(pm, o);
  EXPECT_THROW((void)jg::io::parse_torque_choice("sensor"), std::invalid_argument);
  EXPECT_EQ(jg::io::parse_torque_choice("joint"), jg::io::TorqueChoice::joint);
}

TEST_F(RecordingTest, JointTorqueWritesAndReadsBack) {
  jg::io::Recording rec;
  rec.resize(1, 2, false, false, false, false);
  rec.t = {0.0, 0.001};
  rec.tau_j = {{1.5, 2.5}};
  rec.torque_kind = jg::io::TorqueKind::tau_j;
  const std::string path = (dir / "tj.csv").string();
  jg::io::write_recording(path, rec);
  const auto back = jg::io::read_recording(path);
  EXPECT_EQ(back.torque_kind, jg::io::TorqueKind::tau_j);
  EXPECT_EQ(back.tau_j[0][1], 2.5);
}

// Text in the side file that is not UTF-8 (a name from elsewhere) is written replaced,
// never thrown after the CSV was written (issue 14: .csv.tmp and .json.tmp were left behind).
TEST_F(RecordingTest, SideFileTextThatIsNotUtf8IsReplacedAndNothingTemporaryIsLeft) {
  jg::io::Recording rec;
  rec.resize(1, 2, false, false, false, false);
  rec.t = {0.0, 0.001};
  rec.tau_j = {{1.5, 2.5}};
  rec.torque_kind = jg::io::TorqueKind::tau_j;
  rec.meta.scenario = "caf\xe9";
  const std::string path = (dir / "latin1.csv").string();
  jg::io::write_recording(path, rec);
  EXPECT_FALSE(fs::exists(path + ".tmp"));
  EXPECT_FALSE(fs::exists((dir / "latin1.json.tmp").string()));
  EXPECT_EQ(jg::io::read_recording(path).meta.scenario, "caf\xef\xbf\xbd");  // U+FFFD
}

// Issue 29: an unrelated mydata.json beside mydata.csv made the CSV unreadable, and writing
// a recording overwrote it silently.
TEST_F(RecordingTest, ForeignSideFileIsIgnoredAndNeverOverwritten) {
  const auto p = write("mydata.csv", "t,q1,dq1,i1\n0,0,0,0\n0.001,0,0,0\n");
  const std::string foreign = "{\"model\": {\"layers\": 3}, \"owner\": \"someone else\"}\n";
  write("mydata.json", foreign);
  const auto rec = jg::io::read_recording(p);
  ASSERT_EQ(rec.notes.size(), 1U);
  EXPECT_NE(rec.notes[0].find("mydata.json is not a jointguard side file"), std::string::npos) << rec.notes[0];
  EXPECT_EQ(rec.meta.model, "");
  write("mydata.json", "not json at all\n");
  EXPECT_EQ(jg::io::read_recording(p).notes.size(), 1U);
  write("mydata.json", foreign);
  try {
    jg::io::write_recording(p, rec);
    ADD_FAILURE() << "another program's side file was overwritten";
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("mydata.json: the recording's side file would overwrite a file that is not jointguard's"),
              std::string::npos) << e.what();
  }
  std::ifstream in(dir / "mydata.json");
  EXPECT_EQ(std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>()), foreign);
  // Ours (written with the format key) and the key set older versions wrote are overwritten.
  fs::remove(dir / "mydata.json");
  jg::io::write_recording(p, rec);
  EXPECT_EQ(jg::io::classify_side_file((dir / "mydata.json").string()), jg::io::SideFile::ours);
  write("mydata.json", "{\"model\": \"ref3\", \"sample_time\": 0.001, \"scenario\": \"x\", \"seed\": 3}\n");
  EXPECT_EQ(jg::io::classify_side_file((dir / "mydata.json").string()), jg::io::SideFile::ours);
  EXPECT_NO_THROW(jg::io::write_recording(p, rec));
  EXPECT_THROW(jg::io::write_recording((dir / "rec.json").string(), rec), FormatError);
}

// Issue 29: two writers of one output shared "<out>.tmp": one reported success with a file
// mixing both, the other failed on the rename. Each writer now has its own temporary file.
TEST_F(RecordingTest, ConcurrentWritersLeaveOneCompleteRecording) {
  auto make = [](std::size_t samples, double value) {
    jg::io::Recording r;
    r.resize(2, samples, false, true, false, false);
    for (std::size_t k = 0; k < samples; ++k) {
      r.t[k] = 0.001 * static_cast<double>(k);
      for (std::size_t j = 0; j < 2; ++j) r.tau_m[j][k] = value;
    }
    r.meta.scenario = value > 1.5 ? "b" : "a";
    return r;
  };
  const auto a = make(3000, 1.0), b = make(5000, 2.0);
  const std::string out = (dir / "same.csv").string();
  for (int round = 0; round < 20; ++round) {
    std::thread ta([&] { jg::io::write_recording(out, a); });
    std::thread tb([&] { jg::io::write_recording(out, b); });
    ta.join();
    tb.join();
    const auto back = jg::io::read_recording(out);
    const bool is_a = back.samples() == a.samples() && back.tau_m[1].back() == 1.0;
    const bool is_b = back.samples() == b.samples() && back.tau_m[1].back() == 2.0;
    ASSERT_TRUE(is_a || is_b) << "round " << round << ": " << back.samples() << " samples, a mix";
    EXPECT_EQ(back.meta.scenario, is_a ? "a" : "b") << "the side file comes from the other writer";
  }
  std::size_t files = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    ++files;
    EXPECT_EQ(e.path().string().find(".tmp"), std::string::npos) << e.path();
  }
  EXPECT_EQ(files, 2U);
}

TEST_F(RecordingTest, TemporaryFilesAreUniqueAndRemovedUnlessCommitted) {
  const fs::path target = dir / "out.json";
  std::string first;
  {
    jg::io::TempFile t1(target), t2(target);
    EXPECT_NE(t1.path(), t2.path());
    EXPECT_EQ(t1.path().parent_path(), target.parent_path());
    EXPECT_TRUE(fs::exists(t1.path()));
    first = t1.path().string();
    t2.commit();
  }
  EXPECT_FALSE(fs::exists(first));
  EXPECT_TRUE(fs::exists(target));
  EXPECT_THROW(jg::io::write_text_atomic((dir / "no_such_folder" / "x.json").string(), "{}"), FormatError);
  std::size_t files = 0;
  for (const auto& e : fs::directory_iterator(dir)) files += e.is_regular_file() ? 1U : 0U;
  EXPECT_EQ(files, 1U);
}

// SIGINT while a temporary file exists removes it (a large recording's would stay behind).
TEST_F(RecordingTest, InterruptRemovesTheTemporaryFile) {
  const fs::path target = dir / "big.csv";
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    std::signal(SIGINT, SIG_DFL);  // as an interactive shell starts the CLI (a background job ignores it)
    jg::io::TempFile tmp(target);
    const std::string name = tmp.path().string();
    (void)!::write(fds[1], name.c_str(), name.size());
    ::close(fds[1]);
    std::raise(SIGINT);
    ::_exit(0);  // not reached when the handler re-raises
  }
  ::close(fds[1]);
  char buf[4096] = {};
  const ssize_t got = ::read(fds[0], buf, sizeof buf - 1);
  ::close(fds[0]);
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_GT(got, 0);
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGINT) << "status " << status;
  EXPECT_FALSE(fs::exists(std::string(buf, static_cast<std::size_t>(got)))) << buf;
}

// Issue 29: time stamps in milliseconds read as "21000 rows at 1 Hz" and gave link masses
// off by 1000^2. dq against the change of q over t tells the unit.
TEST_F(RecordingTest, TimeStampsInMillisecondsAreRefused) {
  auto csv = [](double t_scale) {
    std::string text = "t,q1,q2,dq1,dq2,tau_m1,tau_m2\n";
    for (int k = 0; k < 400; ++k) {
      const double t = 0.001 * k;
      char row[200];
      std::snprintf(row, sizeof row, "%.9g,%.9g,%.9g,%.9g,%.9g,0,0\n", t * t_scale, 0.5 * std::sin(3.0 * t), 0.2 * t,
                    1.5 * std::cos(3.0 * t), 0.2);
      text += row;
    }
    return text;
  };
  const auto ms = write("t_ms.csv", csv(1000.0));
  const std::string e = error_of(ms);
  EXPECT_NE(e.find("t_ms.csv:1: field 't': the velocities dq are 1000 times the change of q over t"), std::string::npos) << e;
  EXPECT_NE(e.find("milliseconds"), std::string::npos) << e;
  EXPECT_EQ(error_of(write("t_us.csv", csv(1e6))).find("microseconds") != std::string::npos, true);
  EXPECT_EQ(error_of(write("t_s.csv", csv(1.0))), "no error");
  jg::io::ReadOptions o;
  o.time_column = "time";
  auto renamed = csv(1000.0);
  renamed.replace(0, 1, "time");
  EXPECT_NE(error_of(write("time_ms.csv", renamed), o).find("field 'time'"), std::string::npos);
}

TEST(TorqueKindModel, JointTorqueSensorSeesNoRotorInertia) {
  jg::robot::RobotModel m;
  m.joints.resize(2);
  m.joints[0].link.rotor_inertia = 0.4;
  m.joints[1].link.rotor_inertia = 0.2;
  EXPECT_EQ(jg::robot::for_torque_kind(m, jg::io::TorqueKind::tau_m).joints[0].link.rotor_inertia, 0.4);
  EXPECT_EQ(jg::robot::for_torque_kind(m, jg::io::TorqueKind::current).joints[1].link.rotor_inertia, 0.2);
  const auto j = jg::robot::for_torque_kind(m, jg::io::TorqueKind::tau_j);
  EXPECT_EQ(j.joints[0].link.rotor_inertia, 0.0);
  EXPECT_EQ(j.joints[1].link.rotor_inertia, 0.0);
}

// --- regularize -----------------------------------------------------------------------

/// One joint, q = 2 t, dq = 2, torque = t: any error of the time base shows in q - 2 t.
jg::io::Recording ramp(const std::vector<double>& t) {
  jg::io::Recording r;
  r.resize(1, t.size(), false, true, false, false);
  r.t = t;
  for (std::size_t k = 0; k < t.size(); ++k) {
    r.q[0][k] = 2.0 * t[k];
    r.dq[0][k] = 2.0;
    r.tau_m[0][k] = t[k];
  }
  return r;
}

std::vector<double> jittered(double t0, double t1, double step, double jitter, unsigned seed) {
  std::vector<double> t{t0};
  unsigned x = seed;
  while (t.back() < t1) {
    x = x * 1103515245U + 12345U;
    const double u = static_cast<double>((x >> 8) & 0xffffU) / 65535.0;  // 0..1
    t.push_back(t.back() + step * (1.0 - jitter + 2.0 * jitter * u));
  }
  return t;
}

TEST(Regularize, UniformRecordingIsUsedAsRecorded) {
  std::vector<double> t(500);
  for (std::size_t k = 0; k < t.size(); ++k) t[k] = 0.002 * static_cast<double>(k);
  const auto r = ramp(t);
  const auto out = jg::io::regularize(r);
  ASSERT_EQ(out.segments.size(), 1U);
  EXPECT_EQ(out.segments[0].t, r.t);
  EXPECT_EQ(out.report.method, "none (uniform)");
  EXPECT_NEAR(out.report.rate_hz, 500.0, 1e-6);
  EXPECT_NE(out.report.summary().find("uniform: used as recorded"), std::string::npos);
  EXPECT_TRUE(out.segments[0].rows_t.empty()) << "the samples are the rows";
}

TEST(Regularize, JitteredLogIsResampledByTimeStampNotByIndex) {
  // Steps 0.5-1.5 ms around 1 ms: index spacing would drift the clock by many ms.
  const auto r = ramp(jittered(0.0, 2.0, 0.001, 0.5, 3));
  const auto out = jg::io::regularize(r, {}, "jit.csv");
  ASSERT_EQ(out.segments.size(), 1U);
  EXPECT_EQ(out.report.method, "linear by time stamp");
  EXPECT_NEAR(out.report.rate_hz, 1000.0, 1e-9);
  const auto& s = out.segments[0];
  for (std::size_t k = 0; k < s.samples(); ++k) {
    ASSERT_NEAR(s.t[k], s.t.front() + 0.001 * static_cast<double>(k), 1e-12);
    ASSERT_NEAR(s.q[0][k], 2.0 * s.t[k], 1e-9) << "k = " << k;
  }
  EXPECT_NE(out.report.summary().find("resampled jit.csv: "), std::string::npos) << out.report.summary();
  // The rows it interpolated from are kept beside the samples (an effect of one row's state is
  // computed there by the diagnosis), in order and spanning the samples.
  ASSERT_EQ(s.rows_t.size(), r.t.size());
  ASSERT_EQ(s.rows_dq.size(), 1U);
  EXPECT_EQ(s.rows_t, r.t);
  EXPECT_EQ(s.rows_q[0], r.q[0]);
  EXPECT_EQ(s.rows_dq[0], r.dq[0]);
  // A given rate: still on the recording's clock.
  jg::io::RegularizeOptions o;
  o.rate_hz = 125.0;
  const auto slow = jg::io::regularize(r, o);
  EXPECT_TRUE(slow.report.rate_given);
  const auto& z = slow.segments[0];
  EXPECT_NEAR(z.t[100] - z.t[0], 0.8, 1e-12);
  EXPECT_NEAR(z.q[0][100], 2.0 * z.t[100], 1e-9);
}

TEST(Regularize, RepeatedRowsAreDroppedNotInterpolatedThrough) {
  // Every 7th row repeats the previous state under a new time stamp (a logger reading the
  // same state twice): kept, it would bend the ramp.
  auto r = ramp(jittered(0.0, 1.0, 0.001, 0.2, 5));
  std::size_t repeats = 0;
  for (std::size_t k = 7; k < r.samples(); k += 7) {
    r.q[0][k] = r.q[0][k - 1];
    r.dq[0][k] = r.dq[0][k - 1];
    r.tau_m[0][k] = r.tau_m[0][k - 1];
    ++repeats;
  }
  const auto out = jg::io::regularize(r);
  EXPECT_EQ(out.report.repeats_dropped, repeats);
  const auto& s = out.segments[0];
  for (std::size_t k = 0; k < s.samples(); ++k) ASSERT_NEAR(s.q[0][k], 2.0 * s.t[k], 1e-9) << "k = " << k;
}

TEST(Regularize, AStateHeldForLongKeepsItsValueUntilItChanges) {
  // At rest for 0.2 s (identical rows, jittered stamps), then moving: the rest holds.
  auto t = jittered(0.0, 0.5, 0.001, 0.2, 9);
  auto r = ramp(t);
  for (std::size_t k = 0; k < r.samples(); ++k) {
    if (t[k] < 0.2) {
      r.q[0][k] = 0.0;
      r.dq[0][k] = 0.0;
      r.tau_m[0][k] = 0.0;
    }
  }
  const auto out = jg::io::regularize(r);
  const auto& s = out.segments[0];
  for (std::size_t k = 0; k < s.samples() && s.t[k] < 0.195; ++k) ASSERT_EQ(s.q[0][k], 0.0) << "t = " << s.t[k];
}

TEST(Regularize, LongGapsSplitShortSegmentsAreDroppedAndReported) {
  std::vector<double> t;
  for (int k = 0; k < 300; ++k) t.push_back(0.001 * k);            // 0 .. 0.299
  for (int k = 0; k < 2; ++k) t.push_back(0.8 + 0.001 * k);        // 2 rows alone
  for (int k = 0; k < 400; ++k) t.push_back(1.5 + 0.001 * k * 1.01);  // slightly jittered
  t[350] += 0.0004;
  const auto out = jg::io::regularize(ramp(t));
  EXPECT_EQ(out.report.gaps_split, 2U);
  ASSERT_EQ(out.segments.size(), 2U);
  ASSERT_EQ(out.report.dropped.size(), 1U);
  EXPECT_NEAR(out.report.dropped[0].t_begin, 0.8, 1e-12);
  EXPECT_NEAR(out.segments[1].t.front(), 1.5, 1e-12);
  EXPECT_EQ(out.report.longest(), 1U);
  EXPECT_NE(out.report.summary().find("into 2 segments"), std::string::npos) << out.report.summary();
  // With a larger split threshold the gaps are bridged instead.
  jg::io::RegularizeOptions o;
  o.max_gap_s = 1.0;
  const auto one = jg::io::regularize(ramp(t), o);
  EXPECT_EQ(one.segments.size(), 1U);
  EXPECT_EQ(one.report.gaps_bridged, 2U);
}

TEST(Regularize, TooShortIsRefusedWithAReason) {
  for (const std::size_t n : {1U, 2U}) {
    std::vector<double> t(n);
    for (std::size_t k = 0; k < n; ++k) t[k] = 0.001 * static_cast<double>(k);
    try {
      (void)jg::io::regularize(ramp(t), {}, "short.csv");
      ADD_FAILURE() << n << " rows accepted";
    } catch (const FormatError& e) {
      EXPECT_NE(std::string(e.what()).find("short.csv: field 't'"), std::string::npos) << e.what();
    }
  }
  jg::io::RegularizeOptions o;
  o.rate_hz = 1e9;
  EXPECT_THROW((void)jg::io::regularize(ramp(jittered(0.0, 10.0, 0.001, 0.3, 1)), o), FormatError);
}
}  // namespace

// One trace writer for replay and the host-in-the-loop runs: header from the joint ids,
// t to 1 us, every digit of the estimate, rows to the shortest column.
TEST(TraceCsv, HeaderDigitsAndShortestColumn) {
  const std::string text = jg::io::trace_csv({0.0, 0.001, 0.002}, {{1.0, -0.123456789012, 2.0}, {3.5, 4.25}}, {2, 5});
  EXPECT_EQ(text, "t,mu2,mu5\n0.000000,1,3.5\n0.001000,-0.123456789,4.25\n");
  EXPECT_EQ(jg::io::joint_ids_1_to(3), (std::vector<int>{1, 2, 3}));
}
