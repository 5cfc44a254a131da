// fovea plot: draws the figures of a data file a command wrote (figures.json of `fovea
// latency` and `fovea sweep report`, OUT.json of `gaze plot` and `density --out`) again,
// e.g. after installing matplotlib, or after editing tools/plots/.
#include <fstream>
#include <iostream>

#include <nlohmann/json.hpp>

#include "command.hpp"
#include "figures.hpp"
#include "fovea/core/error.hpp"
#include "fovea/core/json.hpp"

namespace fovea::tools::cmd_plot {
namespace {

constexpr const char* kHelp = R"(usage: fovea plot DATA.json

Draws the figures described by DATA.json as PNG and SVG next to it, with matplotlib: the
data files `fovea latency` and `fovea sweep report` write (figures.json), and those `fovea
gaze plot` and `fovea density --out` write beside their figure (same stem, .json).

The interpreter is $FOVEA_PYTHON, else /usr/bin/python3 when present, else python3 on
PATH; it needs matplotlib (Debian: python3-matplotlib). The scripts are tools/plots/*.py,
built into this program.

Exit status: 0 when drawn, 2 on an invalid data file, 1 when the figures could not be drawn.
)";

int run(std::vector<std::string> argv) {
  if (std::find(argv.begin(), argv.end(), "--help") != argv.end()) {
    std::cout << kHelp;
    return 0;
  }
  const Args a(argv, {}, {}, 1);
  if (a.positional().size() != 1) throw core::InputError("plot needs DATA.json (see --help)");
  const std::string& path = a.positional()[0];
  std::ifstream in(path);
  if (!in) throw core::InputError(path + ": cannot open");
  const nlohmann::json j = core::parse_json_or_discarded(in);
  if (!j.is_object() || !j.contains("figure") || !j["figure"].is_string())
    throw core::InputError(path + ": not a figure data file (no \"figure\" field)");
  const std::string family = j["figure"];
  if (family != "charts" && family != "gaze" && family != "density")
    throw core::InputError(path + ": \"figure\" is \"" + family + "\", expected charts, gaze or density");
  return draw_figures(family, path, std::cerr) ? 0 : 1;
}

}  // namespace

FOVEA_COMMAND(plot_command, "plot", "draw the figures of a data file (matplotlib; PNG and SVG)", run);

}  // namespace fovea::tools::cmd_plot
