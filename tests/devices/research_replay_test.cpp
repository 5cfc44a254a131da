// Replay as a researcher checks it: event statistics against known ground truth at every
// sampling rate, vendor blink marks, 2-D geometry from files and URIs, data quality, kept
// messages, and the fuzz findings on gaze files and HID captures kept as regressions.

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <thread>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "fovea/core/clock.hpp"
#include "fovea/core/error.hpp"
#include "fovea/devices/analysis.hpp"
#include "fovea/devices/hid_stream.hpp"
#include "fovea/devices/readers.hpp"
#include "fovea/devices/screen.hpp"
#include "fovea/devices/timeline.hpp"
#include "scripted.hpp"
#include "test_util.hpp"

using namespace fovea::devices;
using fovea::core::InputError;
using fovea::core::TimeNs;
using fovea::devices::test::scratch_dir;
using fovea::devices::test::VectorStream;
using fovea::devices::test::read_all;
using fovea::devices::test::write_gz;
using fovea::devices::test::write_text;

namespace {

constexpr double kPi = 3.14159265358979323846;

glm::dvec3 dir_az_el(double az, double el) {  // (right, up) angles on the sphere -> view direction
  const double a = az * kPi / 180, e = el * kPi / 180;
  return {std::sin(a) * std::cos(e), std::sin(e), -std::cos(a) * std::cos(e)};
}

// Ground truth: fixations with white tracker noise (0.03° RMS per axis), saccades with a
// raised-cosine position profile and the main-sequence duration D = 2.2·A + 21 ms, and
// untracked runs (blinks flagged blink, dropouts flagged lost). Sampled at `rate` Hz.
struct Script {
  struct Step {
    enum Kind { Fixate, Saccade, Blink, Lost } kind;
    double ms, az, el;  // Saccade: target; Fixate: duration
  };
  std::vector<Step> steps;
  std::vector<GazeSample> sample(double rate, std::uint64_t seed) const {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> noise(0, 0.03);
    std::vector<GazeSample> out;
    double az = 0, el = 0, t_ms = 0;
    const double dt = 1000.0 / rate;
    double next = 0;  // time of the next sample, ms
    auto emit_until = [&](double end_ms, auto&& at, std::uint32_t flags) {
      for (; next < end_ms; next += dt) {
        const glm::dvec2 p = at(next);
        GazeSample s;
        s.t_ns = s.device_time_ns = s.host_time_ns = std::llround(next * 1e6);
        s.combined.flags = flags;
        s.combined.confidence = flags == kTracked ? 1 : 0;
        s.combined.dir = dir_az_el(p.x + noise(rng), p.y + noise(rng));
        s.left = s.right = s.combined;
        out.push_back(s);
      }
    };
    for (const Step& st : steps) {
      if (st.kind == Step::Saccade) {
        const double a = std::hypot(st.az - az, st.el - el), d = 2.2 * a + 21;
        const double az0 = az, el0 = el, t0 = t_ms;
        emit_until(t_ms + d, [&](double t) {
          const double u = 0.5 - 0.5 * std::cos(kPi * (t - t0) / d);
          return glm::dvec2(az0 + u * (st.az - az0), el0 + u * (st.el - el0));
        }, kTracked);
        az = st.az, el = st.el, t_ms += d;
      } else {
        emit_until(t_ms + st.ms, [&](double) { return glm::dvec2(az, el); },
                   st.kind == Step::Fixate ? kTracked : st.kind == Step::Blink ? kBlink : kLost);
        t_ms += st.ms;
      }
    }
    return out;
  }
};

GazeSummary summary_of(std::vector<GazeSample> v) {
  VectorStream s(std::move(v));
  SummaryParams p;
  p.infer_blinks = false;
  return summarize(s, p);
}

}  // namespace

// The I-VT velocity is taken over its whole window at the start and after every gap: no
// saccade is invented where the first interval after a restart is noise alone.
TEST(IvtAtEveryRate, PureFixationWithOneBlinkAndOneDropoutHasNoSaccade) {
  using S = Script::Step;
  const Script sc{{{S::Fixate, 1200, 0, 0}, {S::Blink, 150, 0, 0}, {S::Fixate, 1000, 0, 0}, {S::Lost, 100, 0, 0},
                   {S::Fixate, 1000, 0, 0}}};
  for (double rate : {60.0, 120.0, 250.0, 500.0, 1000.0, 2000.0}) {
    const GazeSummary s = summary_of(sc.sample(rate, 7));
    EXPECT_EQ(s.saccades, 0u) << rate << " Hz";
    EXPECT_EQ(s.fixations, 3u) << rate << " Hz";
    EXPECT_EQ(s.blinks, 1u) << rate << " Hz";
  }
}

TEST(IvtAtEveryRate, SevenKnownSaccadesAreCountedOnceEach) {
  using S = Script::Step;
  const Script sc{{{S::Fixate, 400, 0, 0}, {S::Saccade, 0, 3, 0},   {S::Fixate, 400, 0, 0}, {S::Saccade, 0, 3, 8},
                   {S::Fixate, 300, 0, 0}, {S::Blink, 180, 0, 0},   {S::Fixate, 400, 0, 0}, {S::Saccade, 0, -9, 2},
                   {S::Fixate, 350, 0, 0}, {S::Saccade, 0, 6, -4},  {S::Fixate, 300, 0, 0}, {S::Lost, 120, 0, 0},
                   {S::Fixate, 400, 0, 0}, {S::Saccade, 0, 6, 11},  {S::Fixate, 300, 0, 0}, {S::Saccade, 0, -5, 11},
                   {S::Fixate, 450, 0, 0}, {S::Saccade, 0, 0, 0},   {S::Fixate, 400, 0, 0}}};
  for (double rate : {60.0, 120.0, 250.0, 500.0, 1000.0, 2000.0}) {
    const GazeSummary s = summary_of(sc.sample(rate, 11));
    EXPECT_EQ(s.saccades, 7u) << rate << " Hz";
    EXPECT_EQ(s.blinks, 1u) << rate << " Hz";
  }
}

// Precision as Holmqvist et al. 2012 define it, on white noise of known RMS: STD = √2·σ
// (two axes), RMS-S2S = √2·STD for white noise (Niehorster et al. 2020); data loss exact.
TEST(DataQuality, PrecisionAndDataLossMatchTheNoise) {
  using S = Script::Step;
  const Script sc{{{S::Fixate, 2000, 0, 0}, {S::Blink, 200, 0, 0}, {S::Fixate, 1000, 0, 0}, {S::Lost, 100, 0, 0},
                   {S::Fixate, 1000, 0, 0}}};
  const GazeSummary s = summary_of(sc.sample(500, 3));
  const double sigma = 0.03;
  EXPECT_NEAR(s.quality.std_deg, std::sqrt(2.0) * sigma, 0.004);
  EXPECT_NEAR(s.quality.rms_s2s_deg, 2.0 * sigma, 0.006);
  EXPECT_EQ(s.quality.fixations_measured, 3u);
  EXPECT_NEAR(s.quality.data_loss, 150.0 / 2150.0, 1e-9);  // 100 blink + 50 lost samples of 2150
  EXPECT_NEAR(s.quality.data_loss_excluding_blinks, 50.0 / 2050.0, 1e-9);
}

// Pupil Neon marks blinks with "blink id"; the drifting gaze inside them is no measurement.
TEST(NeonBlinks, BlinkIdIsReadAndItsGazeNotClassified) {
  std::ostringstream csv;
  csv << "section id,recording id,timestamp [ns],gaze x [px],gaze y [px],worn,fixation id,blink id,azimuth [deg],elevation [deg]\n";
  const std::int64_t t0 = 1700000000000000000;
  int blink = 0;
  for (int i = 0; i < 200 * 4; ++i) {  // 4 s at 200 Hz; blinks at 1.0–1.2 s and 2.5–2.7 s
    const double t = i / 200.0;
    const bool in_blink = (t >= 1.0 && t < 1.2) || (t >= 2.5 && t < 2.7);
    if (in_blink && (i == 200 || i == 500)) ++blink;
    double x = 800 + (t >= 2.0 ? 200 : 0), y = 600;
    if (in_blink) y += 400 * std::sin((t - (t < 2 ? 1.0 : 2.5)) * kPi / 0.2);  // the lid drags the gaze
    csv << "s,r," << t0 + std::int64_t(i) * 5'000'000 << "," << x << "," << y << ",1.0,," << (in_blink ? std::to_string(blink) : "")
        << ",0,0\n";
  }
  auto r = open_reader(write_text("gaze.csv", csv.str()), SourceOptions{});
  EXPECT_TRUE(r->reports_blinks());
  SummaryParams p;
  p.infer_blinks = false;
  const GazeSummary s = summarize(*r, p);
  EXPECT_EQ(s.blinks, 2u);
  EXPECT_EQ(s.saccades, 1u);  // the one at 2 s
  EXPECT_EQ(s.blink_samples, 80u);
}

// Neon events.csv and EyeLink MSG lines reach the message sink, on the recording's clock.
TEST(RecordingMessages, EyelinkMsgAndNeonEventsArePassedOn) {
  const std::string asc =
      "** CONVERTED FROM x.edf\nMSG\t1000 DISPLAY_COORDS 0 0 1919 1079\nMSG\t1002 TRIALID 3\n"
      "START\t1004 \tLEFT\tSAMPLES\tEVENTS\nSAMPLES\tGAZE\tLEFT\tRATE\t500.00\n"
      "1004\t960.0\t540.0\t1000.0\t...\nINPUT\t1005\t127\n1006\t961.0\t540.0\t1000.0\t...\nMSG\t1006 -12 stimulus, onset\n";
  auto r = open_reader(write_text("rec.asc", asc), SourceOptions{});
  std::vector<RecordingMessage> m;
  r->set_message_sink([&](const RecordingMessage& x) { m.push_back(x); });
  read_all(*r);
  ASSERT_EQ(m.size(), 4u);
  EXPECT_EQ(m[1].text, "TRIALID 3");
  EXPECT_EQ(m[1].device_time_ns, 1'002'000'000);
  EXPECT_EQ(m[2].kind, "input");
  EXPECT_EQ(m[3].text, "-12 stimulus, onset");
  EXPECT_EQ(r->time_origin_ns(), 1'004'000'000);

  const std::string dir = scratch_dir();
  std::ofstream(dir + "/events.csv") << "recording id,timestamp [ns],name,type\nr,1700000000100000000,recording.begin,recording\n"
                                        "r,1700000000500000000,target shown,\n";
  std::ofstream(dir + "/gaze.csv") << "section id,recording id,timestamp [ns],gaze x [px],gaze y [px],worn\n"
                                      "s,r,1700000000200000000,800,600,1\n";
  auto n = open_reader(dir + "/gaze.csv", SourceOptions{});
  m.clear();
  n->set_message_sink([&](const RecordingMessage& x) { m.push_back(x); });
  read_all(*n);
  ASSERT_EQ(m.size(), 2u);
  EXPECT_EQ(m[0].text, "recording.begin (recording)");
  EXPECT_EQ(m[1].device_time_ns, 1700000000500000000);
}

// EyeLink without DISPLAY_COORDS: the GAZE_COORDS raster is used; gaze off the display is
// reported. And with DISPLAY_COORDS present it wins over GAZE_COORDS.
TEST(EyelinkGeometry, GazeCoordsWhenNoDisplayCoordsAndAWarningOffDisplay) {
  SourceOptions o;
  o.screen = parse_screen("1920x1080@95x63", "test");
  const std::string body = "SAMPLES\tGAZE\tLEFT\tRATE\t500.00\n1000\t960.0\t540.0\t1000.0\n1002\t2500.0\t540.0\t1000.0\n";
  auto r = open_reader(write_text("g.asc", "** x\nMSG\t999 GAZE_COORDS 0.00 0.00 1919.00 1079.00\n" + body), o);
  const auto v = read_all(*r);
  ASSERT_EQ(v.size(), 2u);
  EXPECT_NEAR(std::atan2(v[0].combined.dir.x, -v[0].combined.dir.z) * 180 / kPi, 0, 0.05);
  ASSERT_EQ(r->stats().notes.size(), 1u);
  EXPECT_NE(r->stats().notes[0].find("1 of 2 samples lie outside the display (1920x1080"), std::string::npos) << r->stats().notes[0];

  auto both = open_reader(write_text("d.asc", "** x\nMSG\t998 DISPLAY_COORDS 0 0 1023 767\nMSG\t999 GAZE_COORDS 0.00 0.00 1919.00 1079.00\n"
                                              "SAMPLES\tGAZE\tLEFT\tRATE\t500.00\n1000\t512.0\t384.0\t1000.0\n"), o);
  const auto w = read_all(*both);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_NEAR(std::atan2(w[0].combined.dir.x, -w[0].combined.dir.z) * 180 / kPi, 0, 0.05);
  EXPECT_TRUE(both->stats().notes.empty());

  auto none = open_reader(write_text("n.asc", "** x\n" + body), o);
  read_all(*none);
  ASSERT_FALSE(none->stats().notes.empty());
  EXPECT_NE(none->stats().notes[0].find("no DISPLAY_COORDS or GAZE_COORDS"), std::string::npos);
}

// An 11.17° saccade on a 531 x 299 mm monitor seen from 700 mm stays 11.17° when the
// geometry is given (as size and distance, through the URI key), in EyeLink and Pupil Core.
TEST(ScreenGeometry, ElevenDegreeSaccadeKeepsItsAmplitude) {
  const double mm_per_px = 531.0 / 1920, d_px = 700 * std::tan(11.17 * kPi / 180) / mm_per_px;
  std::ostringstream asc, pupil;
  asc << "** x\nMSG\t0 DISPLAY_COORDS 0 0 1919 1079\nSAMPLES\tGAZE\tLEFT\tRATE\t500.00\n";
  pupil << "gaze_timestamp,world_index,confidence,norm_pos_x,norm_pos_y\n";
  for (int i = 0; i < 500; ++i) {  // 1 s at 500 Hz, the saccade at 0.4–0.45 s
    const double t = i * 2.0, u = std::clamp((t - 400) / 50, 0.0, 1.0);
    const double x = 960 + d_px * (0.5 - 0.5 * std::cos(kPi * u)), y = 540;
    asc << 1000 + t << "\t" << x << "\t" << y << "\t1000.0\n";
    pupil << 50 + t / 1000 << ",0,0.99," << x / 1920 << "," << 1 - y / 1080 << "\n";
  }
  for (const auto& [name, text] : {std::pair{"s.asc", asc.str()}, std::pair{"gaze_positions.csv", pupil.str()}}) {
    Recording rec = open_recording("replay:" + write_text(name, text) + "?screen=1920x1080@531x299mm@700mm", SourceOptions{});
    std::vector<GazeEvent> ev;
    SummaryParams p;
    summarize(*rec.stream, p, [&](const GazeEvent& e) { ev.push_back(e); });
    std::vector<GazeEvent> sacc;
    for (const auto& e : ev)
      if (e.kind == GazeEvent::Kind::Saccade) sacc.push_back(e);
    ASSERT_EQ(sacc.size(), 1u) << name;
    EXPECT_NEAR(sacc[0].amplitude_deg, 11.17, 0.15) << name;
  }
  // Without the geometry the same file is stretched over the display's field of view.
  Recording wrong = open_recording(write_text("w.asc", asc.str()), SourceOptions{});
  double amp = 0;
  summarize(*wrong.stream, SummaryParams{}, [&](const GazeEvent& e) {
    if (e.kind == GazeEvent::Kind::Saccade) amp = e.amplitude_deg;
  });
  EXPECT_GT(amp, 20);
}

TEST(ScreenGeometry, ParsedInOnePlaceWithClearErrors) {
  const auto v = parse_screen("1920x1080@531x299mm@700mm", "x");
  EXPECT_EQ(v.width(), 1920);
  EXPECT_NEAR((v.fov().angle_right - v.fov().angle_left) * 180 / kPi, 2 * std::atan(265.5 / 700) * 180 / kPi, 1e-9);
  const auto f = parse_screen("1280x720@90x60", "x");
  EXPECT_NEAR((f.fov().angle_up - f.fov().angle_down) * 180 / kPi, 60, 1e-9);
  for (const char* bad : {"", "1920x1080", "1920x1080@", "0x10@90x60", "10x10@180x60", "10x10@1x1mm", "10x10@1x1mm@0mm",
                          "10.5x10@90x60", "10x10@nanx60"})
    EXPECT_THROW(parse_screen(bad, "--screen"), InputError) << bad;
  try {
    open_gaze_source("synthetic:1?screen=12", SourceOptions{});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("screen"), std::string::npos);
  }
}

TEST(Detection, UnrelatedJsonIsNotTobii) {
  EXPECT_THROW(open_reader(write_text("package.json", "{\"name\": \"x\", \"version\": \"1.0\"}\n"), SourceOptions{}), InputError);
  auto ok = open_reader(write_text("gazedata", "{\"type\":\"gaze\",\"timestamp\":0.1,\"data\":{}}\n"), SourceOptions{});
  EXPECT_EQ(ok->format(), Format::TobiiG3);
}

// ---- Fuzz findings, each input kept ------------------------------------------------------
TEST(FuzzRegression, DeepOrHugeSidecarIsAClearError) {
  const std::string csv = write_text("deep.csv", "t_ns,eye,dir_x,dir_y,dir_z,confidence,flags\n0,C,0,0,-1,1,1\n");
  std::ofstream(csv + ".json") << std::string(60000, '[') << std::string(60000, ']');
  try {
    open_reader(csv, SourceOptions{});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("nested deeper"), std::string::npos) << e.what();
  }
  std::ofstream(csv + ".json") << "{\"x\": \"" << std::string((1 << 20) + 10, 'a') << "\"}";
  EXPECT_THROW(open_reader(csv, SourceOptions{}), InputError);
  std::ofstream(csv + ".json") << "{\"display\": \"small\", \"s\": \"[[[[\"}";  // brackets in strings do not count
  EXPECT_NO_THROW(open_reader(csv, SourceOptions{}));
}

TEST(FuzzRegression, ExtremeTimestampsNeverOverflow) {
  auto r = open_reader(write_text("t.csv", "t_ns,eye,dir_x,dir_y,dir_z,confidence,flags\n"
                                           "-9000000000000000000,C,0,0,-1,1,1\n0,C,0,0,-1,1,1\n"
                                           "9000000000000000000,C,0,0,-1,1,1\n"),
                       SourceOptions{});
  const GazeSummary s = summarize(*r);
  EXPECT_GE(s.duration_s, 0);
  EXPECT_EQ(r->stats().dropped.at("time_overflow"), 1u);
  auto p = open_reader(write_text("gaze_positions.csv", "gaze_timestamp,world_index,confidence,norm_pos_x,norm_pos_y\n"
                                                        "-9000000000,0,1,0.5,0.5\n9000000000,0,1,0.5,0.5\n"),
                       SourceOptions{});
  EXPECT_GE(summarize(*p).duration_s, 0);
}

TEST(FuzzRegression, HugePupilCoordinateIsDroppedNotANaNDirection) {
  auto r = open_reader(write_text("gaze_positions.csv", "gaze_timestamp,world_index,confidence,norm_pos_x,norm_pos_y\n"
                                                        "1.0,0,1,1e308,0.5\n1.1,0,1,0.5,0.5\n"),
                       SourceOptions{});
  const auto v = read_all(*r);
  ASSERT_EQ(v.size(), 1u);
  EXPECT_TRUE(std::isfinite(v[0].combined.dir.x));
  EXPECT_EQ(r->stats().dropped.at("bad_value"), 1u);
}

TEST(FuzzRegression, TruncatedGzipIsReported) {
  std::string text = "t_ns,eye,dir_x,dir_y,dir_z,confidence,flags\n";
  for (int i = 0; i < 20000; ++i) text += std::to_string(std::int64_t(i) * 1'000'000) + ",C,0,0,-1,1,1\n";
  auto whole = open_reader(write_gz("whole.csv.gz", text), SourceOptions{});
  read_all(*whole);
  EXPECT_TRUE(whole->stats().notes.empty());
  const std::string path = write_gz("cut.csv.gz", text);
  std::filesystem::resize_file(path, std::filesystem::file_size(path) / 2);
  auto cut = open_reader(path, SourceOptions{});
  const auto v = read_all(*cut);
  EXPECT_GT(v.size(), 100u);
  EXPECT_LT(v.size(), 20000u);
  ASSERT_EQ(cut->stats().notes.size(), 1u);
  EXPECT_NE(cut->stats().notes[0].find("truncated"), std::string::npos);
}

TEST(FuzzRegression, LoopPeriodOfAHugeSpanDoesNotOverflow) {
  const std::string f = write_text("span.csv", "t_ns,eye,dir_x,dir_y,dir_z,confidence,flags\n0,C,0,0,-1,1,1\n"
                                               "6000000000000000000,C,0.1,0,-1,1,1\n");
  auto src = open_gaze_source("replay:" + f + "?loop=1", SourceOptions{});
  for (TimeNs t : {TimeNs(0), TimeNs(3'000'000'000'000'000'000), TimeNs(9'000'000'000'000'000'000)}) {
    const GazeSample s = src->sample_at(t);
    EXPECT_TRUE(std::isfinite(s.combined.dir.x)) << t;
    // The newest sample measured by t, on the caller's timeline: never negative, never after t.
    EXPECT_GE(s.t_ns, 0) << t;
    EXPECT_LE(s.t_ns, t);
  }
}

// One changed timestamp byte in the shipped capture (2^62 µs): that report is dropped with
// a reason; every time stays non-negative and the duration positive.
TEST(FuzzRegression, HidTimestampOfTwoToTheSixtyTwoMicroseconds) {
  std::ifstream in(fovea::devices::test::source_dir() + "/data/gaze/hid-ms.hidcap");
  std::stringstream ss;
  ss << in.rdbuf();
  std::string text = ss.str();
  const auto pos = text.find("\ninput ", text.find("\ninput 1001136339 10") + 1);  // the second gaze report
  ASSERT_NE(pos, std::string::npos);
  const auto id = text.find(" 10 ", pos + 7);
  text.replace(id + 4, 23, "00 00 00 00 00 00 00 40");  // 8 timestamp bytes, little endian
  hid::HidCaptureStream c(write_text("ts.hidcap", text), SourceOptions{});
  const auto v = read_all(c);
  EXPECT_EQ(c.stats().dropped.at("time_overflow"), 1u);
  ASSERT_GT(v.size(), 10u);
  for (const auto& s : v) ASSERT_GE(s.t_ns, 0);
}

// The emulated device in real time on its own thread: reports arrive when due on the host
// clock (never earlier), with the faults the URI names.
TEST(EmulatedHidRealtime, PacedOnTheHostClockWithFaultsFromTheUri) {
  SourceOptions o;
  const fovea::core::TimeNs opened = fovea::core::now_ns();  // the device's pacing starts after this
  auto s = open_sample_stream("hid-emulated:ms?rate=120&seconds=0.5&realtime=1", o);
  auto* hid = dynamic_cast<hid::HidGazeStream*>(s.get());
  ASSERT_NE(hid, nullptr);
  std::vector<GazeSample> v;
  GazeSample g;
  while (!hid->finished() || s->next(g)) {
    if (s->next(g)) v.push_back(g);
    else std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  while (s->next(g)) v.push_back(g);
  ASSERT_GT(v.size(), 55u);
  // Never earlier than due: a report is due at its device-time offset from the first one
  // after the pacing started. Only a lower bound: a loaded host receives any report late,
  // the first one too (so the receive times may span less than the device times).
  constexpr fovea::core::TimeNs kTimestampStep = 1'000'000;  // the reports' device-time resolution, with margin
  EXPECT_GE(v.back().device_time_ns - v.front().device_time_ns, 400'000'000);
  for (const GazeSample& x : v)
    ASSERT_GE(x.host_time_ns - opened, x.device_time_ns - v.front().device_time_ns - kTimestampStep);

  auto f = open_sample_stream("hid-emulated:compact?rate=120&seconds=2&realtime=1&unplug_after=20&garbage_every=5", o);
  auto* fh = dynamic_cast<hid::HidGazeStream*>(f.get());
  while (!fh->finished()) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  const auto st = fh->stats();
  EXPECT_TRUE(st.disconnected);
  EXPECT_LT(st.samples, 20u);
  EXPECT_GE(st.reports, 19u);
  EXPECT_THROW(open_sample_stream("hid-emulated:ms?realtime=2", o), InputError);
  EXPECT_THROW(open_sample_stream("hid-emulated:ms?stall_every=-1", o), InputError);
}

// A hand-written descriptor: a 62-bit µs Sensor Timestamp (2 padding bits), a 16-bit gaze
// point, and a Status feature with a 32-bit Configuration Status of logical maximum
// 0xFFFFFFFF beside 32-bit calibrated screen sizes (fuzz findings 8 and 9).
TEST(FuzzRegression, HidWideFieldsSaturateAndStampsStayInInt64) {
  const std::vector<std::uint8_t> desc = {
      0x05, 0x12, 0x09, 0x01, 0xa1, 0x01,                                            // page 0x12, Eye Tracker, application
      0x85, 0x10, 0x09, 0x10, 0xa1, 0x00,                                            // report 0x10, Tracking Data
      0x09, 0x20, 0x15, 0x00, 0x27, 0xff, 0xff, 0xff, 0x7f, 0x75, 0x3e, 0x95, 0x01, 0x81, 0x02,  // timestamp, 62 bits
      0x75, 0x02, 0x95, 0x01, 0x81, 0x03,                                            // 2 padding bits
      0x09, 0x24, 0xa1, 0x00, 0x09, 0x21, 0x09, 0x22, 0x15, 0x00, 0x26, 0xff, 0x7f,  // Gaze Point X, Y
      0x75, 0x10, 0x95, 0x02, 0x81, 0x02, 0xc0, 0xc0,
      0x85, 0x13, 0x0a, 0x01, 0x03, 0x15, 0x00, 0x27, 0xff, 0xff, 0xff, 0xff,        // report 0x13: Configuration Status
      0x75, 0x20, 0x95, 0x01, 0xb1, 0x02,
      0x0a, 0x04, 0x02, 0x0a, 0x05, 0x02, 0x15, 0x00, 0x27, 0xff, 0xff, 0xff, 0x7f,  // Calibrated Screen Width, Height
      0x75, 0x20, 0x95, 0x02, 0xb1, 0x02, 0xc0};
  const hid::EyeTrackerCodec codec(desc);
  const std::vector<std::uint8_t> feature = {0x13, 0xff, 0xff, 0xff, 0xff, 0x20, 0xa1, 0x07, 0x00, 0x20, 0xa1, 0x07, 0x00};
  hid::DeviceConfig cfg;
  ASSERT_TRUE(codec.decode_feature(feature, cfg));
  EXPECT_EQ(cfg.configuration_status, std::numeric_limits<int>::max());
  EXPECT_NEAR(cfg.screen_w_m, 0.5, 1e-12);

  hid::GazeMapper m(codec, parse_screen("1000x1000@90x90", "test"));
  m.feature(feature);
  auto report = [](std::uint64_t ts) {
    std::vector<std::uint8_t> r(13, 0);
    r[0] = 0x10;
    for (int i = 0; i < 8; ++i) r[1 + i] = static_cast<std::uint8_t>(ts >> (8 * i));
    r[9] = r[11] = 100;
    return r;
  };
  GazeSample s;
  std::string why;
  EXPECT_TRUE(m.map(report(1000), s, why)) << why;
  EXPECT_FALSE(m.map(report((std::uint64_t(1) << 62) - 5), s, why));  // ~4.6e21 ns: beyond int64
  EXPECT_EQ(why, "time_overflow");
  ASSERT_TRUE(m.map(report(2000), s, why)) << why;
  EXPECT_EQ(s.device_time_ns, 2'000'000);
}

// Gaze 50° and more off the display was replayed as tracked without a word by every reader
// but EyeLink's. One policy for all: samples whose tracked gaze leaves the view are counted
// and reported in the same words.
TEST(OffDisplayGaze, EveryFormatWarnsTheSameWay) {
  SourceOptions o;  // the `small` display: 100° wide
  const auto expect_note = [](GazeReader& r, const std::string& what) {
    read_all(r);
    ASSERT_EQ(r.stats().notes.size(), 1u) << what;
    EXPECT_NE(r.stats().notes[0].find("1 of 2 samples lie outside the display ("), std::string::npos) << what << ": "
                                                                                                       << r.stats().notes[0];
  };
  // The project's format: a direction 60° to the right (the view ends at 50°).
  auto fovea = open_reader(write_text("f.csv", "t_ns,eye,dir_x,dir_y,dir_z,confidence,flags\n0,C,0,0,-1,1,1\n"
                                               "1000000,C,0.866,0,-0.5,1,1\n"), o);
  expect_note(*fovea, "fovea");
  // Pupil Core: normalised x = 3 (far right of the world image).
  auto pupil = open_reader(write_text("gaze_positions.csv", "gaze_timestamp,confidence,norm_pos_x,norm_pos_y\n"
                                                            "1.0,0.9,0.5,0.5\n1.01,0.9,3.0,0.5\n"), o);
  expect_note(*pupil, "pupil-core");
  // Neon: 5000 px right of a 1600-px scene camera.
  auto neon = open_reader(write_text("gaze.csv", "timestamp [ns],gaze x [px],gaze y [px],worn\n"
                                                 "1000,800,600,1\n2000,5000,600,1\n"), o);
  expect_note(*neon, "neon");
  // Tobii G3: gaze2d x = 4.
  auto g3 = open_reader(write_text("gazedata", R"({"type":"gaze","timestamp":1.0,"data":{"gaze2d":[0.5,0.5]}})" "\n"
                                               R"({"type":"gaze","timestamp":1.01,"data":{"gaze2d":[4,0.5]}})" "\n"), o);
  expect_note(*g3, "tobii-g3");
  // Behind the viewer counts as outside too; in-view gaze gives no note.
  auto behind = open_reader(write_text("b.csv", "t_ns,eye,dir_x,dir_y,dir_z,confidence,flags\n0,C,0,0,-1,1,1\n"
                                                "1000000,C,0,0,1,1,1\n"), o);
  expect_note(*behind, "behind");
  auto inside = open_reader(write_text("i.csv", "t_ns,eye,dir_x,dir_y,dir_z,confidence,flags\n0,C,0,0,-1,1,1\n"
                                                "1000000,C,0.5,0,-1,1,1\n"), o);
  read_all(*inside);
  EXPECT_TRUE(inside->stats().notes.empty());
}

namespace {
std::string shipped_capture() {
  std::ifstream in(fovea::devices::test::source_dir() + "/data/gaze/hid-ms.hidcap");
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}
}  // namespace

// HID captures, plain or gzip, are detected by their first line wherever a recording is
// opened (a plain file name, replay:, `fovea render`); they are read like every reader
// (truncated gzip noted) and the format list of a failed detection names them.
TEST(HidCaptureReplay, DetectedPlainAndGzipAndTruncationIsNoted) {
  const std::string text = shipped_capture();
  ASSERT_FALSE(text.empty());
  const std::string plain = write_text("c.hidcap", text), gz = write_gz("c.hidcap.gz", text);
  EXPECT_EQ(detect_format(plain), Format::HidCapture);
  EXPECT_EQ(detect_format(gz), Format::HidCapture);
  auto r = open_reader(gz, SourceOptions{});
  const auto all = read_all(*r);
  EXPECT_GT(all.size(), 100u);
  EXPECT_FALSE(r->reports_blinks());
  auto src = open_gaze_source(plain, SourceOptions{});
  EXPECT_TRUE(src->sample_at(100'000'000).tracked());
  Recording rec = open_recording("hid-capture:" + gz + "?speed=2", SourceOptions{});
  EXPECT_EQ(rec.reader->format(), Format::HidCapture);

  std::string longer;
  const std::string head = text.substr(0, text.find("\ninput ") + 1), body = text.substr(head.size());
  longer = head;
  for (int i = 0; i < 40; ++i) longer += body;  // repeated reports: later ones drop as out of order
  const std::string cut = write_gz("cut.hidcap.gz", longer);
  std::filesystem::resize_file(cut, std::filesystem::file_size(cut) * 2 / 3);
  auto t = open_reader(cut, SourceOptions{});
  read_all(*t);
  bool noted = false;
  for (const auto& n : t->stats().notes) noted = noted || n.find("truncated") != std::string::npos;
  EXPECT_TRUE(noted);

  try {
    (void)detect_format(write_text("x.txt", "hello\n"));
    ADD_FAILURE() << "detected";
  } catch (const fovea::core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("hid-capture"), std::string::npos) << e.what();
  }
}

// The page carries no blink usage: captures infer blinks from 80–500 ms untracked runs, as
// every format without blink marks does (docs/gaze.md). A capture of synthetic gaze with
// blinks through the emulated device finds them.
TEST(HidCaptureReplay, BlinksAreInferredFromUntrackedRuns) {
  const std::string cap = scratch_dir() + "/blinks.hidcap";
  {
    SourceOptions o;
    o.raw_capture = cap;
    auto s = open_sample_stream("hid-emulated:ms?seed=3&rate=120&seconds=20&task=search", o);
    GazeSample g;
    auto* hs = dynamic_cast<hid::HidGazeStream*>(s.get());
    ASSERT_NE(hs, nullptr);
    for (int waits = 0; waits < 30'000 && !hs->finished();)  // at most 30 s
      if (!s->next(g)) {
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
        ++waits;
      }
    hs->stop();
  }
  Recording rec = open_recording(cap, SourceOptions{});
  ASSERT_FALSE(rec.reader->reports_blinks());
  SummaryParams sp;
  sp.infer_blinks = !rec.reader->reports_blinks();
  const GazeSummary sum = summarize(*rec.stream, sp);
  EXPECT_GT(sum.samples, 2000u);
  EXPECT_GE(sum.blinks, 1u);
}

// docs/gaze.md lists speed= and loop= as replay keys: every entry point takes and checks them.
TEST(ReplayKeys, SpeedAndLoopAreTakenEverywhereAndChecked) {
  const std::string f = write_text("k.csv", "t_ns,eye,dir_x,dir_y,dir_z,confidence,flags\n0,C,0,0,-1,1,1\n"
                                            "1000000,C,0,0,-1,1,1\n");
  EXPECT_NO_THROW((void)open_recording(f + "?speed=2&loop=1", SourceOptions{}));
  EXPECT_NO_THROW((void)open_sample_stream("replay:" + f + "?speed=0.5", SourceOptions{}));
  EXPECT_NO_THROW((void)recording_notes(f + "?speed=2", SourceOptions{}));
  EXPECT_THROW((void)open_recording(f + "?speed=0", SourceOptions{}), fovea::core::InputError);
  EXPECT_THROW((void)open_recording(f + "?loop=2", SourceOptions{}), fovea::core::InputError);
}
