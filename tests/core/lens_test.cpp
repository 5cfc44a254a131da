#include "fovea/core/lens.hpp"

#include <cmath>
#include <string>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "fovea/core/display.hpp"
#include "fovea/core/error.hpp"

using namespace fovea::core;

namespace {

// A preset JSON with the given lens section (fove0-like FOV, small raster).
std::string preset_with_lens(const std::string& lens, int w = 100, int h = 110) {
  return R"({"name":"t","width":)" + std::to_string(w) + R"(,"height":)" + std::to_string(h) +
         R"(,"fov_deg":{"left":-50,"right":50,"up":53,"down":-53},"lens":)" + lens + "}";
}

std::string lens_error_of(const std::string& json) {
  try {
    const DisplayPreset d = parse_display(json, "test.json");
    (void)Lens::for_eye(d, Eye::Left);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

bool finite(glm::dvec2 v) { return std::isfinite(v.x) && std::isfinite(v.y); }

}  // namespace

TEST(Lens, EveryPresetHasALensModel) {
  for (const auto& name : display_preset_names()) {
    const DisplayPreset d = load_display(name);
    EXPECT_NE(d.lens.kind, LensModelKind::None) << name;
    EXPECT_FALSE(d.lens.source.empty()) << name << ": document where the numbers come from";
    for (Eye e : {Eye::Left, Eye::Right}) EXPECT_TRUE(Lens::for_eye(d, e).notes().empty()) << name;
  }
}

TEST(Lens, CentreMapsToItself) {
  for (const auto& name : display_preset_names()) {
    const DisplayPreset d = load_display(name);
    for (Eye e : {Eye::Left, Eye::Right}) {
      const Lens lens = Lens::for_eye(d, e);
      for (int c = 0; c < 3; ++c) {
        const Lens::Channel& ch = lens.channel(c);
        const glm::dvec2 t = lens.forward(ch.display_centre).tangent[c];
        const glm::dvec2 expect = lens.uv_to_tangent(ch.source_centre);
        EXPECT_NEAR(t.x, expect.x, 1e-12) << name << " " << c;
        EXPECT_NEAR(t.y, expect.y, 1e-12) << name << " " << c;
        // The optical axis looks straight ahead (tangent 0) in every preset.
        EXPECT_LT(glm::length(expect), 2e-3) << name << " " << eye_name(e) << " " << c;
        // Radial: a small step away from the centre moves the source along the same ray.
        for (double a = 0; a < 6.28; a += 0.7) {
          const glm::dvec2 dir(std::cos(a), std::sin(a));
          const glm::dvec2 step = 1e-3 * dir / ch.to_radial;
          const glm::dvec2 w = (lens.source_uv(c, ch.display_centre + step) - ch.source_centre) / ch.from_radial;
          EXPECT_NEAR(glm::dot(glm::normalize(w), dir), 1.0, 1e-9);
        }
      }
      // The right eye is the left eye's mirror image.
      if (e == Eye::Right) {
        const Lens left = Lens::for_eye(d, Eye::Left);
        const glm::dvec2 uv(0.2, 0.3);
        const glm::dvec2 tl = left.forward(uv).tangent[1], tr = lens.forward({1 - uv.x, uv.y}).tangent[1];
        EXPECT_NEAR(tl.x, -tr.x, 1e-9) << name;
        EXPECT_NEAR(tl.y, tr.y, 1e-9) << name;
      }
    }
  }
}

TEST(Lens, MonotonicInsideTheEdge) {
  for (const auto& name : display_preset_names()) {
    const DisplayPreset d = load_display(name);
    const Lens lens = Lens::for_eye(d, Eye::Left);
    for (int c = 0; c < 3; ++c) {
      const double edge = lens.channel(c).r_edge;
      double prev = -1;
      for (int i = 0; i <= 2000; ++i) {
        const double r = edge * i / 2000;
        const double g = lens.radial(c, r);
        EXPECT_GT(g, prev) << name << " c" << c << " r=" << r;
        EXPECT_GT(lens.radial_derivative(c, r), 0) << name << " c" << c << " r=" << r;
        prev = g;
      }
    }
  }
}

TEST(Lens, RoundTripBelowAThousandthOfAPixel) {
  for (const auto& name : display_preset_names()) {
    const DisplayPreset d = load_display(name);
    for (Eye e : {Eye::Left, Eye::Right}) {
      const Lens lens = Lens::for_eye(d, e);
      const int W = d.width, H = d.height;
      const int step = std::max(1, std::max(W, H) / 160);  // big panels: a 160² lattice of pixels
      double worst = 0;
      int visible = 0;
      for (int y = 0; y < H; y += step)
        for (int x = 0; x < W; x += step) {
          const glm::dvec2 px(x + 0.5, y + 0.5), uv = px / glm::dvec2(W, H);
          const LensSample s = lens.forward(uv);
          if (!s.within_lens) continue;
          bool inside = true;
          for (int c = 0; c < 3; ++c) {
            const glm::dvec2 su = lens.tangent_to_uv(s.tangent[c]);
            inside = inside && su.x >= 0 && su.y >= 0 && su.x <= 1 && su.y <= 1;
          }
          if (!inside) continue;
          ++visible;
          for (int c = 0; c < 3; ++c) {
            const auto back = lens.inverse(c, s.tangent[c]);
            ASSERT_TRUE(back.has_value()) << name << " " << x << "," << y << " c" << c;
            worst = std::max(worst, glm::length((*back - uv) * glm::dvec2(W, H)));
          }
        }
      EXPECT_GT(visible, 100) << name;
      EXPECT_LT(worst, 1e-3) << name << " " << eye_name(e);
    }
  }
}

TEST(Lens, InverseRefusesWhatNoDisplayRadiusShows) {
  const DisplayPreset d = load_display("fove0");
  const Lens lens = Lens::for_eye(d, Eye::Left);
  EXPECT_FALSE(lens.inverse(1, {std::nan(""), 0}).has_value());
  EXPECT_FALSE(lens.inverse(1, {1e9, 0}).has_value());
  const auto centre = lens.inverse(1, {0, 0});
  ASSERT_TRUE(centre.has_value());
  EXPECT_NEAR(centre->x, 0.5, 1e-12);
}

TEST(Lens, NoLensSectionIsTheIdentity) {
  const DisplayPreset d = parse_display(
      R"({"name":"t","width":10,"height":10,"fov_deg":{"left":-40,"right":40,"up":40,"down":-40}})", "t");
  EXPECT_EQ(d.lens.kind, LensModelKind::None);
  const Lens lens = Lens::for_eye(d, Eye::Left);
  const glm::dvec2 uv(0.13, 0.77);
  for (int c = 0; c < 3; ++c) {
    const glm::dvec2 t = lens.forward(uv).tangent[c], expect = lens.uv_to_tangent(uv);
    EXPECT_DOUBLE_EQ(t.x, expect.x);
    EXPECT_DOUBLE_EQ(t.y, expect.y);
  }
}

TEST(Lens, InvalidCoefficientsAreRefusedNamingTheField) {
  const std::string ok_k = R"("k":[0.75,-0.01,0.75,0,3.8],"aberration":[0.999,1.008,1.018],"centre":[0.5,0.5])";
  EXPECT_NE(lens_error_of(preset_with_lens(R"({"model":"panotools",)" + ok_k + R"(,"scale":0})")).find("lens.scale"),
            std::string::npos);
  EXPECT_NE(lens_error_of(preset_with_lens(
                R"({"model":"panotools","k":[0.75,null,0.75,0,3.8],"aberration":[1,1,1],"centre":[0.5,0.5],"scale":1.2})"))
                .find("lens.k[1]"),
            std::string::npos);
  EXPECT_NE(lens_error_of(preset_with_lens(
                R"({"model":"panotools","k":[0,1,0,0,0],"aberration":[1,1,1],"centre":[0.5,0.5],"scale":1.2})"))
                .find("lens.k[0]"),
            std::string::npos);
  EXPECT_NE(lens_error_of(preset_with_lens(
                R"({"model":"panotools","k":[1,0,0,0,0],"aberration":[1,0,1],"centre":[0.5,0.5],"scale":1.2})"))
                .find("lens.aberration[1]"),
            std::string::npos);
  EXPECT_NE(lens_error_of(preset_with_lens(R"({"model":"fisheye"})")).find("lens.model"), std::string::npos);
  const std::string ch = R"({"centre":[0,0],"k":[0,0,0,0]})";
  EXPECT_NE(lens_error_of(preset_with_lens(R"({"model":"vive","aspect":0,"grow_for_undistort":0.5,"red":)" + ch +
                                      R"(,"green":)" + ch + R"(,"blue":)" + ch + "}"))
                .find("lens.aspect"),
            std::string::npos);
  EXPECT_NE(lens_error_of(preset_with_lens(R"({"model":"vive","aspect":0.9,"grow_for_undistort":-1,"red":)" + ch +
                                      R"(,"green":)" + ch + R"(,"blue":)" + ch + "}"))
                .find("lens.grow_for_undistort"),
            std::string::npos);
  EXPECT_NE(lens_error_of(preset_with_lens(R"({"model":"vive","aspect":0.9,"grow_for_undistort":0.5,"red":)" + ch +
                                      R"(,"green":{"centre":[0,0],"k":[0,0,0,-1]},"blue":)" + ch + "}"))
                .find("lens.green.k"),
            std::string::npos);
  // A radial map that turns back almost at once leaves nothing usable: refused.
  EXPECT_NE(lens_error_of(preset_with_lens(
                R"({"model":"panotools","k":[1,0,-1e6,0,0],"aberration":[1,1,1],"centre":[0.5,0.5],"scale":1.2})"))
                .find("no usable lens area"),
            std::string::npos);
}

TEST(Lens, NonMonotonicMapsAreClampedWithANoteAndStayFinite) {
  // g(ρ) = ρ − ρ³ stops increasing at ρ = 1/√3.
  const DisplayPreset d = parse_display(
      preset_with_lens(R"({"model":"panotools","k":[1,0,-1,0,0],"aberration":[1,1,1],"centre":[0.5,0.5],"scale":0.5})"),
      "t");
  const Lens lens = Lens::for_eye(d, Eye::Left);
  ASSERT_FALSE(lens.notes().empty());
  EXPECT_NE(lens.notes()[0].find("stops increasing"), std::string::npos);
  EXPECT_NEAR(lens.channel(1).r_edge, 1 / std::sqrt(3.0), 1e-9);
  EXPECT_TRUE(lens.forward({0.5, 0.5}).within_lens);
  EXPECT_FALSE(lens.forward({0.0, 0.0}).within_lens);
  // A Vive profile with its pole inside the panel: r = 1/√2.
  const std::string ch = R"({"centre":[0,0],"k":[-2,0,0,0]})";
  const DisplayPreset v = parse_display(preset_with_lens(R"({"model":"vive","aspect":0.9,"grow_for_undistort":0.5,"red":)" +
                                                         ch + R"(,"green":)" + ch + R"(,"blue":)" + ch + "}"),
                                        "t");
  const Lens pole = Lens::for_eye(v, Eye::Left);
  EXPECT_FALSE(pole.notes().empty());
  EXPECT_LT(pole.channel(0).r_edge, 1 / std::sqrt(2.0));
  for (const Lens* l : {&lens, &pole})
    for (int y = 0; y <= 64; ++y)
      for (int x = 0; x <= 64; ++x) {
        const LensSample s = l->forward({x / 64.0, y / 64.0});
        for (int c = 0; c < 3; ++c) EXPECT_TRUE(finite(s.tangent[c])) << x << "," << y;
      }
}

TEST(Lens, CutoffBoundsTheLens) {
  const DisplayPreset d = parse_display(
      preset_with_lens(
          R"({"model":"panotools","k":[1,0,0,0,0],"aberration":[1,1,1],"centre":[0.5,0.5],"scale":0.5,"cutoff":0.5})"),
      "t");
  const Lens lens = Lens::for_eye(d, Eye::Left);
  EXPECT_DOUBLE_EQ(lens.channel(0).r_edge, 0.5);
  EXPECT_TRUE(lens.forward({0.5 + 0.24, 0.5}).within_lens);   // ρ = 0.48
  EXPECT_FALSE(lens.forward({0.5 + 0.26, 0.5}).within_lens);  // ρ = 0.52
}
