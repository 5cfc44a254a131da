// Gaze-source URIs ("scheme:body?key=value&..."): the parser and its typed accessors,
// without opening anything (a URI may name devices and files).
#include "../harness.hpp"
#include "source_uri.hpp"

FOVEA_FUZZ_TARGET(gaze_uri) {
  auto u = fovea::devices::parse_source_uri(fovea::fuzz::as_text(data));
  (void)u.take("format");
  (void)u.take("filters");
  for (const char* key : {"speed", "loop", "rate", "seconds", "horizon_ms", "min_confidence", "noise", "dropouts"})
    (void)u.take_number(key, 1.0, -1e9, 1e9);
  u.finish();
}
