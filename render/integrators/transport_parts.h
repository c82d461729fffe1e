// Transport: the four parts the VRL image is the sum of (step-2 design):
//   surface        (a) T_r(s) L(x_s): radiance of the surface the camera ray reaches
//   single         (b) single scattering along the camera segment
//   medium-surface (c) camera-segment point whose next path vertex is a surface
//   multiple       (d) medium-to-medium multiple scattering, by VRLs
#pragma once

#include <array>
#include <string>
#include <string_view>

namespace vrl {

enum class TransportPart { Surface = 0, Single = 1, MediumSurface = 2, Multiple = 3 };
inline constexpr std::array<std::string_view, 4> kTransportPartNames = {"surface", "single", "medium-surface",
                                                                        "multiple"};

// A layer of part (b) beside "single": its light from surface VPLs (surface_vpl.h),
// once per pixel (vrl, vrl-lightcuts); "single" then holds the rest of (b), per
// sample. The image is the sum of the four parts' layers and this one.
inline constexpr std::string_view kSurfaceVplLayerName = "single-vpl";

struct TransportSelection {
    std::array<bool, 4> enabled{true, true, true, true};

    bool has(TransportPart part) const { return enabled[size_t(part)]; }
    // Parses a comma-separated list of part names ("surface,multiple");
    // throws std::invalid_argument naming the bad entry and the valid names.
    static TransportSelection parse(std::string_view list);
    std::string toString() const;
};

}  // namespace vrl
