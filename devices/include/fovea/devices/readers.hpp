#pragma once
// Recorded gaze: streaming readers for the supported file formats (docs/gaze.md) and
// the writer of the project's own format. Readers hold bounded memory whatever the file
// size, drop bad rows with a counted reason, and never reorder samples.
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <string_view>

#include "fovea/devices/gaze.hpp"

namespace fovea::devices {

enum class Format { Fovea, PupilCore, Neon, TobiiG3, EyelinkAsc };
const char* format_name(Format f);           // "fovea", "pupil-core", "neon", "tobii-g3", "eyelink-asc"
Format parse_format(std::string_view name);  // throws core::InputError
Format detect_format(const std::string& path);  // from the first bytes; throws core::InputError

struct ReadStats {
  std::uint64_t lines = 0;    // physical lines read
  std::uint64_t samples = 0;  // samples kept (tracked or not)
  std::uint64_t tracked = 0;  // kept samples whose combined gaze is tracked
  std::map<std::string, std::uint64_t> dropped;  // rows discarded, by reason
  std::size_t peak_buffer_bytes = 0;             // the reader's own buffer accounting
  std::uint64_t dropped_total() const;
};

class GazeReader : public SampleStream {
 public:
  virtual const ReadStats& stats() const = 0;
  virtual Format format() const = 0;
  // Whether the format marks blinks itself (otherwise analysis infers them from gaps).
  virtual bool reports_blinks() const = 0;
  // Metadata from the format or its sidecar (e.g. "display"), as JSON text ("{}" if none).
  virtual std::string metadata_json() const = 0;
};

// Opens FILE with opt.format (or auto-detection). The project's format reads its JSON
// sidecar (FILE + ".json") if present. Throws core::InputError.
std::unique_ptr<GazeReader> open_reader(const std::string& path, const SourceOptions& opt);

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
  void finish();
  std::uint64_t samples() const { return samples_; }

 private:
  std::string path_, tmp_, meta_;
  void* file_ = nullptr;
  bool per_eye_;
  std::uint64_t samples_ = 0;
};

}  // namespace fovea::devices
