#pragma once
// The 2-D surface gaze coordinates refer to (a monitor, a scene camera), as a pinhole View:
// parsed from one text form wherever a source is opened (`--screen`, the `screen=` URI key).
#include <string_view>

#include "fovea/core/view.hpp"

namespace fovea::devices {

// "WxH@HFOVxVFOV"        raster in pixels and a symmetric field of view in degrees
//                        (a calibration given as FOV), e.g. 1920x1080@95x63;
// "WxH@SWxSHmm@Dmm"      raster, the physical size of that raster and the eye's distance
//                        from the screen centre, e.g. 1920x1080@531x299mm@700mm.
// Throws core::InputError naming `where` (e.g. "--screen") and the text.
core::View parse_screen(std::string_view spec, std::string_view where);

}  // namespace fovea::devices
