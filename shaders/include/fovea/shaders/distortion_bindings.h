// Descriptor binding indices of the display stage's distortion pass (lens_distort.comp), one
// definition for the GLSL and compositor/src/distortion.cpp.
#ifndef FOVEA_SHADERS_DISTORTION_BINDINGS_H
#define FOVEA_SHADERS_DISTORTION_BINDINGS_H

#define DISTORT_BINDING_SOURCE 0  // the resolved view (storage image, rgba32f)
#define DISTORT_BINDING_PANEL 1   // the panel (storage image, rgba8)
#define DISTORT_BINDING_OPTICS 2  // per channel 16 floats
#define DISTORT_BINDING_MASK 3    // the hidden-area bitmask
#define DISTORT_BINDING_LUT 4     // the optional optics cache
#define DISTORT_BINDING_COUNT 5

#endif
