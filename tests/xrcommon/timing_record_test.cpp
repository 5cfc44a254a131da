// Timing records: the JSON line, its round trip, and the writer's failure reporting.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "fovea/core/error.hpp"
#include "fovea/core/json.hpp"
#include "fovea/xrcommon/timing_writer.hpp"

namespace fovea::xrcommon {
namespace {

namespace fs = std::filesystem;

TimingRecord sample_record() {
  TimingRecord r;
  r.source = "latency";
  r.clock = TimeBase::Virtual;
  r.frame = 7;
  r.gaze_valid = true;
  r.gaze_sample_ns = 100;
  r.gaze_device_ns = 100;
  r.gaze_receive_ns = 20'000'100;
  r.gaze_read_ns = 21'000'000;
  r.head_pose_ns = 21'000'000;
  r.head_pose_target_ns = 40'000'000;
  r.submit_ns = 30'000'000;
  r.vsync_ns = 40'000'000;
  r.missed_vsyncs = 1;
  r.photon_ns = std::array<PhotonTimes, 2>{PhotonTimes{41, 42, 43}, PhotonTimes{44, 45, 46}};
  r.cpu_ms = {{"trace", 1.5}, {"bad", std::numeric_limits<double>::quiet_NaN()}};
  r.gpu_ms = {{"trace", 2.25}};
  r.fovea_dir = glm::dvec3(0, 0, -1);
  r.true_gaze_dir = glm::dvec3(std::sin(glm::radians(3.0)), 0, -std::cos(glm::radians(3.0)));
  r.extra = {{"layers", std::int64_t(2)}, {"replaced", true}, {"render_ms", std::numeric_limits<double>::infinity()}};
  return r;
}

TEST(TimingRecord, JsonLineRoundTripsAndHasNoNonFiniteNumbers) {
  const TimingRecord r = sample_record();
  const std::string line = to_json_line(r);
  ASSERT_EQ(line.back(), '\n');
  EXPECT_EQ(line.find('\n'), line.size() - 1);
  EXPECT_EQ(line.find("NaN"), std::string::npos);
  EXPECT_EQ(line.find("nan"), std::string::npos);
  EXPECT_EQ(line.find("inf"), std::string::npos);
  const auto j = fovea::core::parse_json(line);
  EXPECT_EQ(j["schema"], "fovea-timing");
  EXPECT_EQ(j["version"], kTimingVersion);
  EXPECT_EQ(j["clock"], "virtual");
  EXPECT_EQ(j["layers"].get<int>(), 2);
  EXPECT_TRUE(j["replaced"].get<bool>());
  EXPECT_EQ(j["render_ms"].get<double>(), 0.0);
  EXPECT_EQ(j["cpu_ms"]["bad"].get<double>(), 0.0);
  EXPECT_NEAR(j["foveal_error_deg"].get<double>(), 3.0, 1e-9);
  EXPECT_TRUE(j["end_call_ns"].is_null());

  const TimingRecord back = parse_timing_record(line, "t.jsonl:1");
  EXPECT_EQ(back.frame, 7);
  EXPECT_EQ(back.clock, TimeBase::Virtual);
  EXPECT_EQ(*back.gaze_receive_ns - *back.gaze_sample_ns, 20'000'000);
  EXPECT_EQ(*back.head_pose_target_ns - *back.head_pose_ns, 19'000'000);
  // A version-1 line from before head_pose_target_ns still reads (the field is optional).
  auto old = fovea::core::parse_json(line);
  old.erase("head_pose_target_ns");
  EXPECT_FALSE(parse_timing_record(old.dump(), "old.jsonl:1").head_pose_target_ns.has_value());
  EXPECT_EQ((*back.photon_ns)[1].end, 46);
  EXPECT_EQ(back.missed_vsyncs, 1);
  ASSERT_EQ(back.gpu_ms.size(), 1u);
  EXPECT_EQ(back.gpu_ms[0].second, 2.25);
  EXPECT_FALSE(back.end_call_ns.has_value());
  EXPECT_NEAR(*back.foveal_error_deg(), 3.0, 1e-9);
  // The session: null when absent, kept when present; a line without it still reads.
  EXPECT_TRUE(j["session"].is_null());
  EXPECT_FALSE(back.session.has_value());
  TimingRecord in_session = r;
  in_session.session = 2;
  EXPECT_EQ(parse_timing_record(to_json_line(in_session), "t.jsonl:2").session, std::optional<std::int64_t>(2));
  EXPECT_FALSE(parse_timing_record(old.dump(), "old.jsonl:1").session.has_value());
}

TEST(TimingRecord, BadLinesNameTheirPlace) {
  const auto message = [](const std::string& line) {
    try {
      parse_timing_record(line, "rec.jsonl:3");
    } catch (const core::InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("{").find("rec.jsonl:3: not JSON"), std::string::npos);
  EXPECT_NE(message("{\"frame\":1}").find("rec.jsonl:3: not a timing record"), std::string::npos);
  EXPECT_NE(message("{\"schema\":\"fovea-timing\",\"version\":99}").find("version 99"), std::string::npos);
  std::string line = to_json_line(sample_record());
  line.replace(line.find("\"virtual\""), 9, "\"sundial\"");
  EXPECT_NE(message(line).find("clock \"sundial\""), std::string::npos);
  line = to_json_line(sample_record());
  line.replace(line.find("\"fovea_dir\":["), 13, "\"fovea_dir\":[1,");
  EXPECT_NE(message(line).find("fovea_dir"), std::string::npos);
}

struct TempDir {
  fs::path path = fs::temp_directory_path() / ("fovea_timing_" + std::to_string(::getpid()));
  TempDir() { fs::create_directories(path); }
  ~TempDir() { fs::remove_all(path); }
};

std::string slurp(const fs::path& p) {
  std::ifstream f(p);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

TEST(TimingWriter, StreamLinesAreReadableAtOnce) {
  TempDir dir;
  TimingWriter w;
  w.open((dir.path / "timing.jsonl").string());
  TimingRecord r = sample_record();
  ASSERT_TRUE(w.write(r));
  r.frame = 8;
  ASSERT_TRUE(w.write(r));
  const std::string text = slurp(dir.path / "timing.jsonl");  // still open
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 2);
  EXPECT_EQ(parse_timing_record(text.substr(text.find('\n') + 1), "x").frame, 8);
  // Moved writers keep writing to the same file.
  TimingWriter moved = std::move(w);
  EXPECT_FALSE(w.is_open());
  EXPECT_TRUE(moved.write(r));
  moved.close();
  EXPECT_EQ(std::count_if(text.begin(), text.end(), [](char c) { return c == '\n'; }), 2);
  const std::string after = slurp(dir.path / "timing.jsonl");
  EXPECT_EQ(std::count(after.begin(), after.end(), '\n'), 3);
}

// Append keeps what the file holds (a second session of the process after the first);
// Stream starts it again.
TEST(TimingWriter, AppendKeepsEarlierRecords) {
  TempDir dir;
  const std::string path = (dir.path / "layer_timing.jsonl").string();
  TimingRecord r = sample_record();
  for (const TimingWriter::Mode mode : {TimingWriter::Mode::Stream, TimingWriter::Mode::Append}) {
    TimingWriter w;
    w.open(path, mode);
    ASSERT_TRUE(w.write(r));
    ++r.frame;
  }
  std::string text = slurp(path);
  ASSERT_EQ(std::count(text.begin(), text.end(), '\n'), 2);
  EXPECT_EQ(parse_timing_record(text.substr(0, text.find('\n')), "x").frame, 7);
  EXPECT_EQ(parse_timing_record(text.substr(text.find('\n') + 1), "x").frame, 8);
  TimingWriter w;
  w.open(path);
  ASSERT_TRUE(w.write(r));
  text = slurp(path);
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1);
}

TEST(TimingWriter, AtomicFileAppearsOnlyWhenComplete) {
  TempDir dir;
  const fs::path out = dir.path / "records.jsonl";
  {
    TimingWriter w;
    w.open(out.string(), TimingWriter::Mode::Atomic);
    ASSERT_TRUE(w.write(sample_record()));
    EXPECT_FALSE(fs::exists(out));
    // Destroyed without close (a failed run): nothing is left behind.
  }
  EXPECT_FALSE(fs::exists(out));
  EXPECT_TRUE(fs::is_empty(dir.path));
  TimingWriter w;
  w.open(out.string(), TimingWriter::Mode::Atomic);
  ASSERT_TRUE(w.write(sample_record()));
  w.close();
  EXPECT_EQ(slurp(out), to_json_line(sample_record()));
}

TEST(TimingWriter, FailuresAreReportedWithThePath) {
  TimingWriter w;
  try {
    w.open("/nonexistent-fovea-dir/timing.jsonl");
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-fovea-dir/timing.jsonl"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(w.write(sample_record()));
  // A full device: the write fails, is reported once, and later writes are ignored.
  if (fs::exists("/dev/full")) {
    w.open("/dev/full");
    EXPECT_FALSE(w.write(sample_record()));
    EXPECT_NE(w.error().find("write failed at frame 7"), std::string::npos) << w.error();
    EXPECT_FALSE(w.is_open());
    EXPECT_FALSE(w.write(sample_record()));
  }
}

}  // namespace
}  // namespace fovea::xrcommon
