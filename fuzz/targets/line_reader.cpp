// The streaming line reader under every text format: plain or gzip bytes, CR/LF, BOM,
// overlong and unterminated lines; read twice (rewind).
#include "../harness.hpp"
#include "line_reader.hpp"

FOVEA_FUZZ_TARGET(line_reader) {
  fovea::devices::detail::LineReader r(fovea::fuzz::scratch_file("lines.txt", fovea::fuzz::as_text(data)));
  fovea::devices::detail::Line line;
  for (int pass = 0; pass < 2; ++pass) {
    while (r.next(line)) (void)line.text.size();
    r.rewind();
  }
}
