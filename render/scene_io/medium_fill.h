// Filling a scene with smoke: the paper's benchmarks (STAIRCASE, VEACH-LAMP) are
// public surface scenes with a homogeneous medium added everywhere. `--medium
// "sigmaS=0.1,sigmaA=0.02[,g=0.3]"` does the same to any scene without media.
//
// The fill medium surrounds the camera and every emitter; opaque shapes keep
// declaring no media, so rays crossing them keep the fill. Glass shapes
// (dielectric, roughdielectric) that declare no media also keep it: thin panes
// and hollow shells are right, solid glass gets smoke inside (documented
// approximation, listed in SceneDescription::approximations when it applies).
#pragma once

#include "render/description/scene_description.h"

#include <string_view>

namespace vrl {

// Parses "sigmaS=a,sigmaA=b[,g=c]" (each coefficient one number or r:g:b,
// per scene unit; g in (-1, 1), default 0 = isotropic). Throws
// std::invalid_argument naming the bad entry.
MediumDescription parseFillMedium(std::string_view text);

// Adds `medium` as the scene's only medium, around the camera and the point
// and spot emitters. Throws SceneError if the scene already declares media.
void fillWithMedium(SceneDescription& scene, MediumDescription medium);

}  // namespace vrl
