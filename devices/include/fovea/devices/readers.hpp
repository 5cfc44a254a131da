#pragma once
// Recorded gaze: streaming readers for the supported file formats (docs/gaze.md) and
// the writer of the project's own format. Readers hold bounded memory whatever the file
// size, drop bad rows with a counted reason, and never reorder samples.
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "fovea/devices/gaze.hpp"

namespace fovea::devices {

// HidCapture: a raw HID capture (docs/hid.md), replayed through the device's decoder.
enum class Format { Fovea, PupilCore, Neon, TobiiG3, EyelinkAsc, HidCapture };
const char* format_name(Format f);  // "fovea", "pupil-core", "neon", "tobii-g3", "eyelink-asc", "hid-capture"
Format parse_format(std::string_view name);  // throws core::InputError
// From the first bytes (decompressed if gzip); throws core::InputError listing the formats.
// The one detection every entry point uses (open_reader, hence replays, `fovea render`, `gaze`).
Format detect_format(const std::string& path);
// The clock a format's own time stamps count on (kept as device_time_ns), for sidecars.
const char* device_clock_name(Format f);

struct ReadStats {
  std::uint64_t lines = 0;    // physical lines read
  std::uint64_t samples = 0;  // samples kept (tracked or not)
  std::uint64_t tracked = 0;  // kept samples whose combined gaze is tracked
  std::map<std::string, std::uint64_t> dropped;  // rows discarded, by reason
  std::size_t peak_buffer_bytes = 0;             // the reader's own buffer accounting
  // What a user must know about the data that is not a dropped row (a truncated gzip file,
  // gaze outside the display, a geometry fallback), one sentence each, at most kMaxNotes.
  std::vector<std::string> notes;
  static constexpr std::size_t kMaxNotes = 16;
  std::uint64_t dropped_total() const;
};

// A message or event a format carries beside the gaze (EyeLink MSG/INPUT/BUTTON lines,
// Pupil Neon events.csv), on the recording's own clock (device time, ns).
struct RecordingMessage {
  core::TimeNs device_time_ns = 0;
  std::string kind;  // "msg", "input", "button", "event"
  std::string text;
};

class GazeReader : public SampleStream {
 public:
  virtual const ReadStats& stats() const = 0;
  virtual Format format() const = 0;
  // Whether the format marks blinks itself (otherwise analysis infers them from gaps).
  virtual bool reports_blinks() const = 0;
  // Metadata from the format or its sidecar (e.g. "display"), as JSON text ("{}" if none).
  virtual std::string metadata_json() const = 0;
  // The device time of t = 0 (the first kept sample); valid once a sample was read.
  virtual core::TimeNs time_origin_ns() const = 0;
  // Receives the format's messages in file order while the file is read (none by default).
  using MessageSink = std::function<void(const RecordingMessage&)>;
  void set_message_sink(MessageSink sink) { sink_ = std::move(sink); }

 protected:
  MessageSink sink_;
};

// Opens FILE with opt.format (or auto-detection). The project's format reads its JSON
// sidecar (FILE + ".json") if present. Throws core::InputError.
std::unique_ptr<GazeReader> open_reader(const std::string& path, const SourceOptions& opt);

// A recording named like a replay source: "replay:FILE?format=F&min_confidence=C&screen=G&
// filters=..." or a plain FILE (the common URI keys of docs/gaze.md, no timeline keys). The
// reader gives the stats and messages; `stream` is what to walk (the reader, or the filter
// stages on top of it). Throws core::InputError.
struct Recording {
  std::unique_ptr<SampleStream> stream;
  GazeReader* reader = nullptr;  // owned by `stream`
  SourceOptions options;         // after the URI's keys
};
Recording open_recording(std::string_view uri, const SourceOptions& opt);
// The reader's notes on a recording (gaze outside the display, a truncated file, a missing
// raster) from one streaming pass, for tools that replay through a GazeSource and would not
// see them; empty for sources that are not recordings.
std::vector<std::string> recording_notes(std::string_view uri, const SourceOptions& opt);

// Writes the project's format: CSV `t_ns,eye,dir_x,dir_y,dir_z,confidence,flags` (one row
// per eye: combined, left, right) and the sidecar FILE.json. Both appear atomically at
// finish(); a writer destroyed without finish() leaves nothing behind.
class FoveaCsvWriter {
 public:
  // `metadata_json`: a JSON object merged into the sidecar (display, generator, ...).
  FoveaCsvWriter(const std::string& path, const std::string& metadata_json, bool per_eye = true);
  ~FoveaCsvWriter();
  FoveaCsvWriter(const FoveaCsvWriter&) = delete;
  FoveaCsvWriter& operator=(const FoveaCsvWriter&) = delete;
  void write(const GazeSample& s);
  // Replaces the metadata merged into the sidecar (known only after the samples, e.g. the
  // time base); the sidecar is written at finish().
  void set_metadata(const std::string& metadata_json);
  void finish();
  std::uint64_t samples() const { return samples_; }

 private:
  std::string path_, tmp_, meta_;
  void* file_ = nullptr;
  bool per_eye_;
  std::uint64_t samples_ = 0;
};

}  // namespace fovea::devices
