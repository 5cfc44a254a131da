#pragma once
// Figures are drawn by matplotlib (docs/figures.md): a command writes the data of its
// figures to a JSON file, then runs the embedded script of that figure family
// (tools/plots/<family>.py with the shared fovea_plot.py) on it with Python, which writes
// every figure as PNG and SVG next to the data. Without Python or matplotlib the data is
// still written and a note says how to draw the figures later (`fovea plot DATA`).
#include <ostream>
#include <string>

namespace fovea::tools {

// The interpreter: $FOVEA_PYTHON when set, else /usr/bin/python3 (the one Debian's
// python3-matplotlib is for) when present, else python3 found on PATH.
std::string python_interpreter();

// Runs the script of `family` (charts, gaze, density) on the data file. Returns true when the
// figures were drawn; otherwise writes to `log` a warning naming the script and the reason,
// and the command that draws them, and returns false (never throws for a plot failure).
bool draw_figures(const std::string& family, const std::string& data_path, std::ostream& log);

}  // namespace fovea::tools
