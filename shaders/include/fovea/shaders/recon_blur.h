// GLSL only: the peripheral blur's kernel width from the acuity model, shared by the display-
// space (recon_blur.comp) and grid-space (recon_grid_blur.comp) passes:
// σ(e) = σ_fovea / m(e) degrees, m of P4 Eq. 1 as core::acuity::m (reconstruct::blur_sigma_deg).
#ifndef FOVEA_SHADERS_RECON_BLUR_H
#define FOVEA_SHADERS_RECON_BLUR_H
float rg_blur_sigma_deg(float e_deg, float sigma_fovea_deg) {
  float acuity = e_deg <= 5.79 ? 1.0 : 7.49 / ((0.3 * e_deg + 1.0) * (0.3 * e_deg + 1.0));
  return sigma_fovea_deg / acuity;
}
#endif
