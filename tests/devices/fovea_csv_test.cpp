#include <cmath>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "fovea/core/error.hpp"
#include "fovea/devices/analysis.hpp"
#include "fovea/devices/readers.hpp"
#include "fovea/devices/synthetic.hpp"
#include "test_util.hpp"

using namespace fovea::devices;
using fovea::devices::test::scratch_dir;
using fovea::devices::test::write_text;

TEST(FoveaCsv, WriterReaderRoundTrip) {
  SynthParams p;
  p.seed = 3;
  p.seconds = 2;
  SyntheticStream src(p);
  const std::string path = scratch_dir() + "/rt.csv";
  {
    FoveaCsvWriter w(path, R"({"display":"small"})");
    GazeSample s;
    while (src.next(s)) w.write(s);
    w.finish();
  }
  auto r = open_reader(path, SourceOptions{});
  EXPECT_EQ(r->format(), Format::Fovea);
  EXPECT_NE(r->metadata_json().find("\"display\":\"small\""), std::string::npos);
  src.rewind();
  GazeSample a, b;
  std::uint64_t n = 0;
  while (src.next(a)) {
    ASSERT_TRUE(r->next(b)) << n;
    EXPECT_EQ(a.t_ns, b.t_ns);
    EXPECT_EQ(a.combined.flags, b.combined.flags);
    EXPECT_EQ(a.left.flags, b.left.flags);
    EXPECT_LT(fovea::core::angle_deg(a.combined.dir, b.combined.dir), 1e-3);
    EXPECT_LT(fovea::core::angle_deg(a.right.dir, b.right.dir), 1e-3);
    EXPECT_NEAR(a.combined.confidence, b.combined.confidence, 1e-3);
    ++n;
  }
  EXPECT_FALSE(r->next(b));
  EXPECT_EQ(n, 240u);
  EXPECT_EQ(r->stats().samples, 240u);
  EXPECT_TRUE(r->stats().dropped.empty());
}

TEST(FoveaCsv, WriterLeavesNothingWithoutFinish) {
  const std::string path = scratch_dir() + "/none.csv";
  {
    FoveaCsvWriter w(path, "{}");
    w.write(GazeSample{});
  }
  EXPECT_FALSE(std::filesystem::exists(path));
  EXPECT_FALSE(std::filesystem::exists(path + ".json"));
}

TEST(FoveaCsv, HostileInputIsCountedNotFatal) {
  // BOM, CRLF, reordered + extra columns, then one bad row of each kind, and a truncated
  // last line. Only combined rows: per-eye gaze copies the combined one.
  const std::string text =
      "\xEF\xBB\xBF" "eye,t_ns,extra,dir_x,dir_y,dir_z,confidence,flags\r\n"
      "combined,1000,x,0,0,-1,1,1\r\n"
      "combined,2000,x,0.1,0,-1,1,1\r\n"
      "combined,2000,x,0.1,0,-1,1,1\r\n"        // duplicate time
      "combined,1500,x,0.1,0,-1,1,1\r\n"        // goes backwards
      "combined,3000,x,0.1\r\n"                 // missing columns
      "combined,3000,x,,0,-1,1,1\r\n"           // empty field
      "combined,3000,x,nan,0,-1,1,1\r\n"        // NaN
      "combined,3000,x,0,inf,-1,1,1\r\n"        // Inf
      "combined,3000,x,0,0,-1,1,9\r\n"          // unknown flags
      "combined,3000,x,0,0,0,1,1\r\n"           // zero direction
      "combined,3000,x,0,abc,-1,1,1\r\n"        // not a number
      "\r\n"
      "combined,4000,x,0,0,-1,0,2\r\n"          // a blink: kept, not tracked
      "combined,5000,x,0,0,-1,1,1,\r\n"         // trailing comma: an extra empty column, fine
      "combined,6000,x,0,0,-";                  // truncated last line
  auto r = open_reader(write_text("hostile.csv", text), SourceOptions{});
  std::vector<GazeSample> got;
  GazeSample s;
  while (r->next(s)) got.push_back(s);
  ASSERT_EQ(got.size(), 4u);
  EXPECT_EQ(got[0].t_ns, 0);  // rebased to the first sample
  EXPECT_EQ(got[0].device_time_ns, 1000);
  EXPECT_EQ(got[1].t_ns, 1000);
  EXPECT_EQ(got[2].combined.flags, kBlink);
  EXPECT_EQ(got[2].left.flags, kBlink);
  EXPECT_EQ(got[3].t_ns, 4000);
  EXPECT_NEAR(glm::length(got[1].combined.dir), 1.0, 1e-12);
  const auto& d = r->stats().dropped;
  EXPECT_EQ(d.at("duplicate_time"), 1u);
  EXPECT_EQ(d.at("non_monotonic_time"), 1u);
  EXPECT_EQ(d.at("missing_columns"), 1u);
  EXPECT_EQ(d.at("empty_field"), 1u);
  EXPECT_EQ(d.at("non_finite"), 2u);
  EXPECT_EQ(d.at("bad_value"), 2u);
  EXPECT_EQ(d.at("bad_number"), 1u);
  EXPECT_EQ(d.at("truncated_last_line"), 1u);
  EXPECT_EQ(r->stats().samples, 4u);
  EXPECT_EQ(r->stats().tracked, 3u);
}

TEST(FoveaCsv, PerEyeRowsGroupAndCombine) {
  const std::string text =
      "t_ns,eye,dir_x,dir_y,dir_z,confidence,flags\n"
      "0,left,0.1,0,-1,0.9,1\n"
      "0,right,-0.1,0,-1,0.8,1\n"
      "0,right,-0.1,0,-1,0.8,1\n"  // same eye twice at one time
      "10,left,0,0,-1,1,2\n"
      "10,right,0.2,0,-1,1,1\n";
  auto r = open_reader(write_text("eyes.csv", text), SourceOptions{});
  GazeSample a, b, c;
  ASSERT_TRUE(r->next(a));
  ASSERT_TRUE(r->next(b));
  EXPECT_FALSE(r->next(c));
  EXPECT_NEAR(a.combined.dir.x, 0.0, 1e-12);  // normalised mean of the two eyes
  EXPECT_NEAR(a.combined.confidence, 0.8, 1e-12);
  EXPECT_TRUE(b.combined.tracked());  // one eye tracked is enough
  EXPECT_GT(b.combined.dir.x, 0.1);
  EXPECT_EQ(r->stats().dropped.at("duplicate_time"), 1u);
}

TEST(FoveaCsv, MissingHeaderColumnIsAnError) {
  const std::string p = write_text("bad.csv", "t_ns,eye,dir_x,dir_y,confidence,flags\n0,combined,0,0,1,1\n");
  auto r = open_reader(p, SourceOptions{});
  GazeSample s;
  try {
    r->next(s);
    FAIL() << "expected InputError";
  } catch (const fovea::core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.csv:1"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("dir_z"), std::string::npos) << e.what();
  }
}

TEST(FoveaCsv, EmptyOrHeaderOnlyYieldsNoSample) {
  auto r = open_reader(write_text("h.csv", "t_ns,eye,dir_x,dir_y,dir_z,confidence,flags\n"), SourceOptions{});
  GazeSample s;
  EXPECT_FALSE(r->next(s));
  EXPECT_EQ(r->stats().samples, 0u);
  EXPECT_THROW(open_reader(write_text("e.csv", ""), SourceOptions{}), fovea::core::InputError);  // undetectable
  EXPECT_THROW(open_reader(scratch_dir() + "/missing.csv", SourceOptions{}), fovea::core::InputError);
}

TEST(FoveaCsv, ShippedDefaultRecordingIsSmallAndUsable) {
  const std::string path = fovea::devices::test::source_dir() + "/data/gaze/default.csv";
  ASSERT_TRUE(std::filesystem::exists(path)) << path;
  EXPECT_LT(std::filesystem::file_size(path), 200u * 1024);
  auto r = open_reader(path, SourceOptions{});
  EXPECT_NE(r->metadata_json().find("fovea gaze synth"), std::string::npos);  // documented origin
  const GazeSummary s = summarize(*r);
  EXPECT_GE(s.duration_s, 3.0);
  EXPECT_GT(s.valid_fraction(), 0.9);
  EXPECT_GT(s.saccades, 5u);
  EXPECT_TRUE(r->stats().dropped.empty());
}
