#include "gaze_arg.hpp"

#include <cstdlib>
#include <sstream>
#include <vector>

#include "fovea/core/error.hpp"

namespace fovea::tools {

namespace {
std::vector<double> numbers(const std::string& key, const std::string& s, size_t n) {
  std::vector<double> out;
  std::stringstream ss(s);
  std::string part;
  while (std::getline(ss, part, ',')) {
    char* end = nullptr;
    const double v = std::strtod(part.c_str(), &end);
    if (part.empty() || *end != '\0') throw core::InputError("--" + key + ": \"" + part + "\" is not a number");
    out.push_back(v);  // NaN/Inf are accepted on purpose: the distributions fall back safely
  }
  if (out.size() != n)
    throw core::InputError("--" + key + ": expected " + std::to_string(n) + " comma-separated numbers, got \"" + s + "\"");
  return out;
}
}  // namespace

glm::dvec3 parse_gaze(const Args& a, const core::View& view) {
  if (a.has("gaze") && a.has("gaze-dir")) throw core::InputError("give either --gaze or --gaze-dir, not both");
  if (auto d = a.opt("gaze-dir")) {
    const auto v = numbers("gaze-dir", *d, 3);
    return {v[0], v[1], v[2]};
  }
  const auto v = numbers("gaze", a.str("gaze", "0.5,0.5"), 2);
  return view.pixel_to_dir({v[0] * view.width(), v[1] * view.height()});
}

}  // namespace fovea::tools
