// The project's own CSV format with its JSON sidecar: the input up to a line "#sidecar"
// is the CSV, the rest FILE.json (absent when there is no marker).
#include <filesystem>

#include "../gaze_options.hpp"
#include "../harness.hpp"

FOVEA_FUZZ_TARGET(gaze_fovea) {
  const auto [csv, sidecar] = fovea::fuzz::split(fovea::fuzz::as_text(data), "\n#sidecar\n");
  const std::string path = fovea::fuzz::scratch_file("gaze.csv", csv);
  if (sidecar.empty()) std::filesystem::remove(path + ".json");
  else fovea::fuzz::scratch_file("gaze.csv.json", sidecar);
  fovea::fuzz::drain_recording(path, "fovea");
}
