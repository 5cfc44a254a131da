#include "fovea/core/lens_params.hpp"

#include <cmath>

#include <nlohmann/json.hpp>

#include "fovea/core/error.hpp"
#include "json_input.hpp"

namespace fovea::core {

namespace {

using nlohmann::json;

class Reader {
 public:
  explicit Reader(std::string_view origin) : origin_(origin) {}

  [[noreturn]] void fail(const std::string& field, const std::string& what) const {
    throw InputError(origin_ + ": lens." + field + ": " + what);
  }

  double number(const json& j, const std::string& key, const std::string& path) const {
    if (!j.contains(key) || !j[key].is_number()) fail(path + key, "missing or not a number");
    const double v = j[key].get<double>();
    if (!std::isfinite(v)) fail(path + key, "not finite");
    return v;
  }

  template <size_t N>
  std::array<double, N> numbers(const json& j, const std::string& key, const std::string& path) const {
    if (!j.contains(key) || !j[key].is_array() || j[key].size() != N)
      fail(path + key, "expected an array of " + std::to_string(N) + " numbers");
    std::array<double, N> out{};
    for (size_t i = 0; i < N; ++i) {
      const json& e = j[key][i];
      // nlohmann parses NaN/Infinity literals nowhere, but null stands in for them in many writers.
      if (!e.is_number()) fail(path + key + "[" + std::to_string(i) + "]", "not a number");
      out[i] = e.get<double>();
      if (!std::isfinite(out[i])) fail(path + key + "[" + std::to_string(i) + "]", "not finite");
    }
    return out;
  }

  glm::dvec2 vec2(const json& j, const std::string& key, const std::string& path) const {
    const auto a = numbers<2>(j, key, path);
    return {a[0], a[1]};
  }

 private:
  std::string origin_;
};

ViveChannel read_vive_channel(const Reader& r, const json& lens, const char* name) {
  if (!lens.contains(name) || !lens[name].is_object()) r.fail(name, "missing (an object with centre and k)");
  const std::string path = std::string(name) + ".";
  ViveChannel c;
  c.centre = r.vec2(lens[name], "centre", path);
  const auto k = r.numbers<4>(lens[name], "k", path);
  c.k = k;
  // d(0) = 1 + k4 is the magnification at the centre; the radial map r·d(r) must increase there.
  if (!(1.0 + k[3] > 0)) r.fail(path + "k", "1 + k4 must be positive (the radial map must increase at the lens centre)");
  return c;
}

}  // namespace

const char* lens_model_name(LensModelKind k) {
  switch (k) {
    case LensModelKind::Vive: return "vive";
    case LensModelKind::Panotools: return "panotools";
    case LensModelKind::None: break;
  }
  return "none";
}

LensParams parse_lens_params(std::string_view text, std::string_view origin) {
  LensParams p;
  const json j = detail::parse_json_input(text, origin);
  if (!j.is_object() || !j.contains("lens")) return p;
  const Reader r(origin);
  const json& lens = j["lens"];
  if (!lens.is_object()) r.fail("", "must be an object");
  if (!lens.contains("model") || !lens["model"].is_string()) r.fail("model", "missing (\"vive\" or \"panotools\")");
  const std::string model = lens["model"].get<std::string>();
  if (lens.contains("source")) {
    if (!lens["source"].is_string()) r.fail("source", "must be a string");
    p.source = lens["source"].get<std::string>();
  }

  if (model == "vive") {
    p.kind = LensModelKind::Vive;
    ViveLens& v = p.vive;
    v.aspect = r.number(lens, "aspect", "");
    v.grow = r.number(lens, "grow_for_undistort", "");
    if (lens.contains("r2_cutoff")) v.r2_cutoff = r.number(lens, "r2_cutoff", "");
    if (!(v.aspect > 1e-3 && v.aspect < 1e3)) r.fail("aspect", "must be in (0.001, 1000)");
    if (!(v.grow > -1 + 1e-6)) r.fail("grow_for_undistort", "must be greater than -1");
    if (v.r2_cutoff < 0) r.fail("r2_cutoff", "must be positive (or 0 for none)");
    v.channel = {read_vive_channel(r, lens, "red"), read_vive_channel(r, lens, "green"),
                 read_vive_channel(r, lens, "blue")};
  } else if (model == "panotools") {
    p.kind = LensModelKind::Panotools;
    PanotoolsLens& t = p.panotools;
    t.k = r.numbers<5>(lens, "k", "");
    t.aberration = r.numbers<3>(lens, "aberration", "");
    t.centre = r.vec2(lens, "centre", "");
    t.scale = r.number(lens, "scale", "");
    if (lens.contains("cutoff")) t.cutoff = r.number(lens, "cutoff", "");
    if (!(t.scale > 1e-6)) r.fail("scale", "must be positive (ρ is measured in units of it)");
    for (int c = 0; c < 3; ++c)
      if (!(t.aberration[c] > 1e-6)) r.fail("aberration[" + std::to_string(c) + "]", "must be positive");
    if (!(t.k[0] > 0)) r.fail("k[0]", "must be positive (the radial map must increase at the lens centre)");
    if (t.cutoff < 0) r.fail("cutoff", "must be positive (or 0 for none)");
  } else {
    r.fail("model", "unknown model \"" + model + "\" (expected \"vive\" or \"panotools\")");
  }
  return p;
}

}  // namespace fovea::core
