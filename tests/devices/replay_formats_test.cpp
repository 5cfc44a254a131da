#include <sys/resource.h>

#include <cmath>
#include <cstdio>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "fovea/core/error.hpp"
#include "fovea/devices/analysis.hpp"
#include "fovea/devices/readers.hpp"
#include "test_util.hpp"

using namespace fovea::devices;
using fovea::devices::test::scratch_dir;
using fovea::devices::test::read_all;
using fovea::devices::test::write_gz;
using fovea::devices::test::write_text;

namespace {
SourceOptions symmetric_screen(int w, int h, double hfov, double vfov) {
  SourceOptions o;
  o.screen = fovea::core::View(fovea::core::Fov::from_degrees(-hfov / 2, hfov / 2, vfov / 2, -vfov / 2), w, h);
  return o;
}
// Direction -> (x right, y up) angles in degrees for readable expectations.
double az(glm::dvec3 d) { return std::atan2(d.x, -d.z) * 180 / M_PI; }
double el(glm::dvec3 d) { return std::atan2(d.y, -d.z) * 180 / M_PI; }
}  // namespace

TEST(PupilCore, NormalisedBottomLeftAndGazeNormals) {
  const std::string h =
      "gaze_timestamp,world_index,confidence,norm_pos_x,norm_pos_y,base_data,gaze_point_3d_x,gaze_point_3d_y,"
      "gaze_point_3d_z,eye_center0_3d_x,eye_center0_3d_y,eye_center0_3d_z,gaze_normal0_x,gaze_normal0_y,"
      "gaze_normal0_z,eye_center1_3d_x,eye_center1_3d_y,eye_center1_3d_z,gaze_normal1_x,gaze_normal1_y,gaze_normal1_z\n";
  const std::string text = h +
      "100.000,1,0.99,0.5,0.5,100.0-0 100.0-1,0,0,500,20,0,0,0.1,0.2,1,-20,0,0,0,0,1\n"
      "100.004,1,0.95,0.0,1.0,100.004-0,,,,,,,,,,,,,,,\n"   // 2D only: top-left corner
      "100.004,1,0.95,0.0,1.0,100.004-1,,,,,,,,,,,,,,,\n"   // duplicated timestamp
      "100.008,1,0.20,0.5,0.5,100.008-0,,,,,,,,,,,,,,,\n"   // low confidence: kept, lost
      "100.012,1,0.9,0.5\n"                                  // missing columns
      "100.016,1,0.9,NaN,0.5,x,,,,,,,,,,,,,,,\n";
  auto r = open_reader(write_text("gaze_positions.csv", text), symmetric_screen(1280, 720, 90, 60));
  EXPECT_EQ(r->format(), Format::PupilCore);
  const auto v = read_all(*r);
  ASSERT_EQ(v.size(), 3u);
  EXPECT_NEAR(az(v[0].combined.dir), 0, 1e-9);
  EXPECT_NEAR(el(v[0].combined.dir), 0, 1e-9);
  // gaze_normal0 = right eye, camera frame y down -> view y up (negative here).
  EXPECT_NEAR(v[0].right.dir.x / -v[0].right.dir.z, 0.1, 1e-9);
  EXPECT_NEAR(v[0].right.dir.y / -v[0].right.dir.z, -0.2, 1e-9);
  EXPECT_NEAR(glm::length(v[0].left.dir - glm::dvec3(0, 0, -1)), 0, 1e-12);
  EXPECT_NEAR(az(v[1].combined.dir), -45, 1e-9);  // (0, 1) = top-left
  EXPECT_NEAR(el(v[1].combined.dir), 30, 1e-9);
  EXPECT_EQ(v[1].t_ns, 4'000'000);
  EXPECT_EQ(v[2].combined.flags, kLost);
  EXPECT_NEAR(v[2].combined.confidence, 0.2, 1e-12);
  EXPECT_EQ(r->stats().dropped.at("duplicate_time"), 1u);
  EXPECT_EQ(r->stats().dropped.at("missing_columns"), 1u);
  EXPECT_EQ(r->stats().dropped.at("non_finite"), 1u);
}

// Older Pupil Player exports name the first columns timestamp and index (gaze_timestamp and
// world_index later); both are detected and read alike.
TEST(PupilCore, OlderExportsNameTheTimeColumnTimestamp) {
  const std::string text =
      "timestamp,index,confidence,norm_pos_x,norm_pos_y,base_data,gaze_point_3d_x\n"
      "146663.960698,0,0.9,0.5,0.5,146663.960698-0,-6.9\n"
      "146663.964698,0,0.9,0.0,1.0,146663.964698-0,-6.9\n";
  const std::string path = write_text("old_gaze_positions.csv", text);
  EXPECT_EQ(detect_format(path), Format::PupilCore);
  auto r = open_reader(path, symmetric_screen(1280, 720, 90, 60));
  const auto v = read_all(*r);
  ASSERT_EQ(v.size(), 2u);
  EXPECT_EQ(v[1].t_ns, 4'000'000);
  EXPECT_EQ(v[0].device_time_ns, 146663960698000);
  EXPECT_NEAR(az(v[1].combined.dir), -45, 1e-9);
  EXPECT_NEAR(el(v[1].combined.dir), 30, 1e-9);
  // Neither name: refused with the header named.
  auto bad = open_reader(write_text("no_time.csv", "t,confidence,norm_pos_x,norm_pos_y\n1,1,0.5,0.5\n"),
                         [] { SourceOptions o; o.format = "pupil-core"; return o; }());
  GazeSample s;
  try {
    bad->next(s);
    ADD_FAILURE() << "a header without a time column was read";
  } catch (const fovea::core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("gaze_timestamp (or timestamp)"), std::string::npos) << e.what();
  }
}

TEST(Neon, ScenePixelsWornAndAngles) {
  const std::string text =
      "section id,recording id,timestamp [ns],gaze x [px],gaze y [px],worn,fixation id,blink id,azimuth [deg],elevation [deg]\r\n"
      "s,r,1700000000000000000,800,600,1.0,1,,0,0\r\n"
      "s,r,1700000000005000000,0,0,1.0,,,-51.5,38.5\r\n"
      "s,r,1700000000010000000,800,600,0.0,,,0,0\r\n"
      "s,r,1700000000015000000,,,1.0,,,10,5\r\n"        // no pixels: azimuth/elevation fallback
      "s,r,1700000000020000000,,,1.0,,,,\r\n"           // nothing usable
      "s,r,1700000000005000000,800,600,1.0,,,0,0\r\n"  // backwards
      "s,r,17000000000250";                              // truncated
  auto r = open_reader(write_text("gaze.csv", text), SourceOptions{});  // default: Neon scene camera
  EXPECT_EQ(r->format(), Format::Neon);
  const auto v = read_all(*r);
  ASSERT_EQ(v.size(), 4u);
  EXPECT_NEAR(az(v[0].combined.dir), 0, 1e-9);
  EXPECT_NEAR(az(v[1].combined.dir), -51.5, 1e-6);  // top-left of 1600x1200 @ 103x77
  EXPECT_NEAR(el(v[1].combined.dir), 38.5, 1e-6);
  EXPECT_EQ(v[2].combined.flags, kLost);            // not worn
  EXPECT_NEAR(std::asin(v[3].combined.dir.y) * 180 / M_PI, 5, 1e-9);
  EXPECT_EQ(v[3].t_ns, 15'000'000);
  EXPECT_EQ(r->stats().dropped.at("empty_field"), 1u);
  EXPECT_EQ(r->stats().dropped.at("non_monotonic_time"), 1u);
  EXPECT_EQ(r->stats().dropped.at("truncated_last_line"), 1u);
}

TEST(TobiiG3, GzipNdjsonWithLostTrackingAndBadLines) {
  const std::string text =
      R"({"type":"gaze","timestamp":1.00,"data":{"gaze2d":[0.5,0.5],"gaze3d":[0,0,100],)"
      R"("eyeleft":{"gazeorigin":[30,0,0],"gazedirection":[0.1,0,1],"pupildiameter":3},)"
      R"("eyeright":{"gazeorigin":[-30,0,0],"gazedirection":[0,0.1,1],"pupildiameter":3}}})" "\n"
      R"({"type":"gaze","timestamp":1.01,"data":{}})" "\n"
      R"({"type":"gaze","timestamp":1.02,"data":{"gaze2d":[0,0],"eyeleft":{}}})" "\n"
      R"({"type":"gaze","timestamp":1.03,"data":{"gaze2d":[0.5,0.5]}} trailing)" "\n"
      R"({"type":"gaze","data":{}})" "\n"
      R"({"type":"sync","timestamp":1.04})" "\n"
      R"({"type":"gaze","timestamp":1.05,"data":{"gaze2d":[0.5,)";
  auto r = open_reader(write_gz("gazedata.gz", text), SourceOptions{});
  EXPECT_EQ(r->format(), Format::TobiiG3);
  const auto v = read_all(*r);
  ASSERT_EQ(v.size(), 3u);
  EXPECT_TRUE(v[0].tracked());
  // Glasses frame x left, y up, z forward -> view (−x, y, −z).
  EXPECT_NEAR(v[0].left.dir.x / -v[0].left.dir.z, -0.1, 1e-9);
  EXPECT_NEAR(v[0].right.dir.y / -v[0].right.dir.z, 0.1, 1e-9);
  EXPECT_EQ(v[1].combined.flags, kLost);  // data = {}
  EXPECT_EQ(v[1].t_ns, 10'000'000);
  EXPECT_NEAR(az(v[2].combined.dir), -47.5, 1e-6);  // top-left of the 95x63 scene camera
  EXPECT_NEAR(el(v[2].combined.dir), 31.5, 1e-6);
  EXPECT_FALSE(v[2].left.tracked());
  EXPECT_EQ(r->stats().dropped.at("bad_json"), 1u);
  EXPECT_EQ(r->stats().dropped.at("missing_field"), 1u);
  EXPECT_EQ(r->stats().dropped.at("truncated_last_line"), 1u);
}

TEST(EyelinkAsc, MonocularBinocularMissingAndBlinks) {
  const std::string mono =
      "** CONVERTED FROM test.edf\n"
      "MSG\t1000 DISPLAY_COORDS 0 0 1919 1079\n"
      // A calibration's tables as EyeLink writes them (indented numbers): not samples.
      ">>>>>>> CALIBRATION (HV13,P-CR) FOR RIGHT: <<<<<<<<<\n"
      "   5107.4  224.55  525.97 -1.4154  21.426 \n"
      "\t-3904  6893 -1664  8322\n"
      "START\t1000 \tRIGHT\tSAMPLES\tEVENTS\n"
      "SAMPLES\tGAZE\tRIGHT\tRATE\t500.00\tTRACKING\tCR\tFILTER\t2\n"
      "1000\t  960.0\t  540.0\t  800.0\t...\n"
      "1002\t   .\t   .\t    0.0\t...\n"
      "SBLINK R 1004\n"
      "1004\t   .\t   .\t    0.0\t...\n"
      "EBLINK R 1004 1006 4\n"
      "1006\t    0.0\t    0.0\t  800.0\t...\n"
      "1008\t  nan\t  0.0\t  800.0\t...\n"
      "1010\t  960.0\n"
      "END\t1010 \tSAMPLES\tEVENTS\tRES\t 38.00\t 34.00\n";
  auto r = open_reader(write_text("mono.asc", mono), symmetric_screen(1920, 1080, 60, 40));
  EXPECT_EQ(r->format(), Format::EyelinkAsc);
  EXPECT_TRUE(r->reports_blinks());
  const auto v = read_all(*r);
  ASSERT_EQ(v.size(), 4u);
  EXPECT_NEAR(az(v[0].combined.dir), 0, 1e-6);
  EXPECT_EQ(v[1].combined.flags, kLost);
  EXPECT_EQ(v[2].combined.flags, kBlink);
  EXPECT_NEAR(az(v[3].right.dir), -30, 1e-6);
  EXPECT_NEAR(el(v[3].right.dir), 20, 1e-6);
  EXPECT_EQ(v[3].t_ns, 6'000'000);
  EXPECT_EQ(r->stats().dropped.at("non_finite"), 1u);
  EXPECT_EQ(r->stats().dropped.at("missing_columns"), 1u);

  const std::string bino =
      "** DATE: today\n"
      "MSG\t5 DISPLAY_COORDS 0 0 959 539\n"  // a different raster: scaled to the view
      "SAMPLES\tGAZE\tLEFT\tRIGHT\tRATE\t1000.00\n"
      "10\t 480.0\t 270.0\t 900.0\t   .\t   .\t   0.0\t.....\n"
      "11\t 0.0\t 0.0\t 900.0\t 959.999\t 539.999\t 900.0\t.....\n";
  auto b = open_reader(write_text("bino.asc", bino), symmetric_screen(1920, 1080, 60, 40));
  const auto w = read_all(*b);
  ASSERT_EQ(w.size(), 2u);
  EXPECT_TRUE(w[0].left.tracked());
  EXPECT_FALSE(w[0].right.tracked());
  EXPECT_TRUE(w[0].combined.tracked());
  EXPECT_NEAR(az(w[0].combined.dir), 0, 1e-6);
  EXPECT_NEAR(az(w[1].left.dir), -30, 1e-6);
  EXPECT_NEAR(az(w[1].right.dir), 30, 1e-3);
  EXPECT_NEAR(az(w[1].combined.dir), 0, 1e-3);

  auto href = open_reader(write_text("href.asc", "** x\nSAMPLES\tHREF\tLEFT\tRATE\t500\n1 2 3 4\n"), SourceOptions{});
  GazeSample s;
  EXPECT_THROW(href->next(s), fovea::core::InputError);
}

// 2 kHz recordings converted without fractional times repeat each millisecond's time stamp:
// the second sample is half a millisecond later (the SAMPLES line's RATE), not a duplicate.
// Written fractions are kept as written; at 1 kHz a repeated time stays a duplicate.
TEST(EyelinkAsc, TwoKilohertzWholeMillisecondsGetTheSamplePeriod) {
  const auto times = [](const std::string& rate, const std::string& samples) {
    const std::string text = "** CONVERTED FROM t.edf\nSTART\t100 \tRIGHT\tSAMPLES\tEVENTS\n"
                             "SAMPLES\tGAZE\tRIGHT\tRATE\t" + rate + "\tTRACKING\tCR\tFILTER\t2\n" + samples;
    auto r = open_reader(write_text("rate.asc", text), symmetric_screen(1920, 1080, 60, 40));
    std::vector<fovea::core::TimeNs> t;
    for (const GazeSample& s : read_all(*r)) t.push_back(s.device_time_ns);
    return std::make_pair(t, r->stats().dropped);
  };
  const std::string line = "\t  960.0\t  540.0\t  800.0\t...\n";
  const auto [whole, whole_dropped] = times("2000.00", "100" + line + "100" + line + "101" + line + "101" + line);
  EXPECT_EQ(whole, (std::vector<fovea::core::TimeNs>{100'000'000, 100'500'000, 101'000'000, 101'500'000}));
  EXPECT_TRUE(whole_dropped.empty());
  const auto [fractional, unused] = times("2000.00", "100" + line + "100.5" + line + "101" + line);
  EXPECT_EQ(fractional, (std::vector<fovea::core::TimeNs>{100'000'000, 100'500'000, 101'000'000}));
  const auto [khz, khz_dropped] = times("1000.00", "100" + line + "100" + line + "101" + line);
  EXPECT_EQ(khz, (std::vector<fovea::core::TimeNs>{100'000'000, 101'000'000}));
  EXPECT_EQ(khz_dropped.at("duplicate_time"), 1u);
}

// Without --screen an EyeLink file gives its own screen: DISPLAY_COORDS and the angular
// resolution on its END line (RES: pixels per degree), a pinhole with the eye RES·180/π
// pixels from the raster's centre. A point RES·180/π·tan 10° right of the centre is 10° out.
TEST(EyelinkAsc, WithoutAScreenTheFileGivesItsOwn) {
  const double d = 35.9 * 180 / M_PI;  // the eye's distance in pixels
  char right10[64];
  std::snprintf(right10, sizeof right10, "%.3f", 512 + d * std::tan(10 * M_PI / 180));
  const std::string body = std::string("MSG\t900 DISPLAY_COORDS 0 0 1023 767\n") +
                           "START\t1000 \tRIGHT\tSAMPLES\tEVENTS\n"
                           "SAMPLES\tGAZE\tRIGHT\tRATE\t500.00\tTRACKING\tCR\tFILTER\t2\n"
                           "1000\t  512.0\t  384.0\t  800.0\t...\n"
                           "1002\t  " + right10 + "\t  384.0\t  800.0\t...\n";
  const std::string with_res =
      write_text("res.asc", "** x\n" + body + "END\t1004 \tSAMPLES\tEVENTS\tRES\t 35.90\t 35.90\n");
  auto r = open_reader(with_res, SourceOptions{});
  auto v = read_all(*r);
  ASSERT_EQ(v.size(), 2u);
  EXPECT_NEAR(az(v[0].combined.dir), 0, 1e-9);
  EXPECT_NEAR(el(v[0].combined.dir), 0, 1e-9);
  EXPECT_NEAR(az(v[1].combined.dir), 10, 1e-3);
  ASSERT_EQ(r->stats().notes.size(), 1u);
  EXPECT_NE(r->stats().notes[0].find("1024x768 px, 28.0 x 21.1 degrees"), std::string::npos) << r->stats().notes[0];
  // A given screen wins: the same pixel through its 60° (the place across the raster, -1..1).
  auto given = open_reader(with_res, symmetric_screen(1920, 1080, 60, 40));
  v = read_all(*given);
  ASSERT_EQ(v.size(), 2u);
  const double across = (512 + d * std::tan(10 * M_PI / 180)) / 512 - 1;
  EXPECT_NEAR(az(v[1].combined.dir), std::atan(across * std::tan(30 * M_PI / 180)) * 180 / M_PI, 1e-3);
  EXPECT_TRUE(given->stats().notes.empty());
  // No RES: the display's view, as for every 2D format.
  auto none = open_reader(write_text("nores.asc", "** x\n" + body), SourceOptions{});
  v = read_all(*none);
  ASSERT_EQ(v.size(), 2u);
  EXPECT_TRUE(none->stats().notes.empty());
}

TEST(Replay, FormatOverrideAndDetectionFailure) {
  SourceOptions o;
  o.format = "neon";
  auto r = open_reader(write_text("whatever.txt", "timestamp [ns],gaze x [px],gaze y [px]\n1,800,600\n"), o);
  EXPECT_EQ(r->format(), Format::Neon);
  o.format = "tobii";
  EXPECT_THROW(open_reader(write_text("x.txt", "a,b\n"), o), fovea::core::InputError);
  EXPECT_THROW(open_reader(write_text("y.txt", "a,b\n1,2\n"), SourceOptions{}), fovea::core::InputError);
  EXPECT_THROW(open_reader(write_text("blank.txt", "\n \r\n\t\n"), SourceOptions{}), fovea::core::InputError);
}

// Detection reads the first line that is not blank (a public Pupil Core export starts with an
// empty line; the readers skip blank lines as well).
TEST(Replay, DetectionSkipsLeadingBlankLines) {
  const std::string pupil = "\n\r\n  \ngaze_timestamp,world_index,confidence,norm_pos_x,norm_pos_y\n"
                            "5.0,0,1.0,0.5,0.5\n5.004,0,1.0,0.25,0.5\n";
  auto r = open_reader(write_text("pupil.csv", pupil), symmetric_screen(1280, 720, 90, 60));
  EXPECT_EQ(r->format(), Format::PupilCore);
  const auto v = read_all(*r);
  ASSERT_EQ(v.size(), 2u);
  EXPECT_NEAR(az(v[1].combined.dir), -26.565, 1e-3);  // x = 0.25: tan⁻¹(½·tan 45°) left
  EXPECT_EQ(detect_format(write_text("eyelink.asc", "\n** CONVERTED FROM x.edf\n")), Format::EyelinkAsc);
  EXPECT_EQ(detect_format(write_text("fovea.csv", "\xEF\xBB\xBF\r\nt_ns,eye,dir_x\n")), Format::Fovea);
}

TEST(Replay, OverlongLineIsDroppedAndBufferStaysBounded) {
  std::string text = "t_ns,eye,dir_x,dir_y,dir_z,confidence,flags\n0,combined,0,0,-1,1,1\n";
  text += "1,combined," + std::string(3 << 20, '7') + ",0,-1,1,1\n";
  text += "2,combined,0,0,-1,1,1\n";
  auto r = open_reader(write_text("long.csv", text), SourceOptions{});
  EXPECT_EQ(read_all(*r).size(), 2u);
  EXPECT_EQ(r->stats().dropped.at("line_too_long"), 1u);
  EXPECT_LE(r->stats().peak_buffer_bytes, (1u << 20) + 3 * 65536);
}

// 10⁷ samples streamed: the reader's own buffer accounting stays at a few chunks and the
// process's peak RSS stays far below the file size. (10⁶ under the sanitizers, for time,
// where only the reader's accounting is checked.)
TEST(Replay, TenMillionSamplesStreamInBoundedMemory) {
#if defined(__SANITIZE_ADDRESS__)
  const long rows = 1'000'000;
#else
  const long rows = 10'000'000;
#endif
  const std::string path = scratch_dir() + "/big.csv";
  {
    std::FILE* f = std::fopen(path.c_str(), "wb");
    ASSERT_TRUE(f);
    std::string buf = "t_ns,eye,dir_x,dir_y,dir_z,confidence,flags\n";
    char line[64];
    for (long i = 0; i < rows; ++i) {
      const int n = std::snprintf(line, sizeof line, "%ld,C,0.%03ld,0,-1,1,1\n", i * 1000, i % 1000);
      buf.append(line, static_cast<std::size_t>(n));
      if (buf.size() > (1 << 20)) {
        std::fwrite(buf.data(), 1, buf.size(), f);
        buf.clear();
      }
    }
    std::fwrite(buf.data(), 1, buf.size(), f);
    std::fclose(f);
  }
  [[maybe_unused]] const auto file_size = std::filesystem::file_size(path);  // read below unless sanitized
  auto r = open_reader(path, SourceOptions{});
  SummaryParams sp;
  const GazeSummary s = summarize(*r, sp);
  std::filesystem::remove(path);
  EXPECT_EQ(s.samples, static_cast<std::uint64_t>(rows));
  EXPECT_EQ(r->stats().dropped_total(), 0u);
  EXPECT_NEAR(s.rate_hz, 1e6, 1);
  EXPECT_LE(r->stats().peak_buffer_bytes, 3u * 65536);
#if !defined(__SANITIZE_ADDRESS__)  // the sanitizer's shadow memory dominates RSS there
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  const double rss = ru.ru_maxrss * 1024.0;
  EXPECT_LT(rss, 0.25 * static_cast<double>(file_size)) << "peak RSS " << rss << " B for a " << file_size << " B file";
#endif
}
