#include "fovea/devices/screen.hpp"

#include <cmath>
#include <numbers>
#include <string>

#include "fovea/core/error.hpp"
#include "text.hpp"

namespace fovea::devices {

namespace {
// "AxB" -> two numbers, with an optional unit suffix on the second.
bool pair(std::string_view s, std::string_view unit, double& a, double& b) {
  if (!unit.empty()) {
    if (s.size() <= unit.size() || s.substr(s.size() - unit.size()) != unit) return false;
    s.remove_suffix(unit.size());
  }
  const auto x = s.find('x');
  return x != std::string_view::npos && detail::parse_double(s.substr(0, x), a) == detail::Num::Ok &&
         detail::parse_double(s.substr(x + 1), b) == detail::Num::Ok;
}
}  // namespace

core::View parse_screen(std::string_view spec, std::string_view where) {
  auto bad = [&](const std::string& why) -> core::InputError {
    return core::InputError(std::string(where) + ": " + why + "; expected WxH@HFOVxVFOV (pixels, degrees, e.g. "
                            "1920x1080@95x63) or WxH@SWxSHmm@Dmm (pixels, screen size and eye distance in mm, e.g. "
                            "1920x1080@531x299mm@700mm); got \"" + std::string(spec) + "\"");
  };
  const auto at = spec.find('@');
  double w = 0, h = 0;
  if (at == std::string_view::npos || !pair(spec.substr(0, at), "", w, h)) throw bad("no raster WxH");
  if (!(w >= 1 && h >= 1 && w <= 65536 && h <= 65536 && w == std::floor(w) && h == std::floor(h)))
    throw bad("the raster must be 1..65536 whole pixels");
  const std::string_view rest = spec.substr(at + 1);
  double hf = 0, vf = 0;
  if (const auto at2 = rest.find('@'); at2 != std::string_view::npos) {
    double sw = 0, sh = 0, d = 0;
    const std::string_view dist = rest.substr(at2 + 1);
    if (!pair(rest.substr(0, at2), "mm", sw, sh) || dist.size() < 3 || dist.substr(dist.size() - 2) != "mm" ||
        detail::parse_double(dist.substr(0, dist.size() - 2), d) != detail::Num::Ok)
      throw bad("cannot read the screen size and distance");
    if (!(sw > 0 && sh > 0 && d > 0 && sw < 1e6 && sh < 1e6 && d < 1e6)) throw bad("sizes and distance must be positive");
    // Full angle subtended by the screen seen from its centre's normal at distance d.
    hf = 2 * std::atan(sw / (2 * d)) * 180 / std::numbers::pi;
    vf = 2 * std::atan(sh / (2 * d)) * 180 / std::numbers::pi;
  } else if (!pair(rest, "", hf, vf)) {
    throw bad("cannot read the field of view");
  }
  if (!(hf > 0 && hf < 179 && vf > 0 && vf < 179)) throw bad("the field of view must lie in (0, 179) degrees");
  return core::View(core::Fov::from_degrees(-hf / 2, hf / 2, vf / 2, -vf / 2), static_cast<int>(w), static_cast<int>(h));
}

}  // namespace fovea::devices
