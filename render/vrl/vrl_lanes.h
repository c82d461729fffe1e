// VrlLanes: a structure-of-arrays copy of a VRL set for the SIMD kernel
// (vrl_kernel.h): one float array per coordinate, flux already multiplied by
// the VRL medium's sigma_s, the medium's HG g (0 where isotropic), padded with
// zero-length VRLs to a multiple of kKernelPadding. Built only where VRLs are
// summed one by one (the plain method): 48 bytes per VRL, beside the 44 of the
// VRLs themselves.
#pragma once

#include "render/vrl/vrl.h"
#include "render/vrl/vrl_kernel.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace vrl {

class Scene;

class VrlLanes {
public:
    VrlLanes() = default;
    VrlLanes(const std::vector<Vrl>& vrls, const Scene& scene);

    size_t size() const { return size_; }
    // The kernel's view of the VRLs from `first` on (first a multiple of kKernelPadding).
    KernelVrls from(size_t first) const;
    size_t memoryBytes() const { return floats_.capacity() * sizeof(float) + media_.capacity() * sizeof(int32_t); }

    static constexpr size_t kBytesPerVrl = 11 * sizeof(float) + sizeof(int32_t);  // kArrays floats and a medium
    // The arrays of KernelVrls, in order; `write` fills entry k of each.
    enum Array { kOriginX, kOriginY, kOriginZ, kDirectionX, kDirectionY, kDirectionZ, kLength, kG, kFluxR, kFluxG, kFluxB, kArrays };
    static_assert(kBytesPerVrl == kArrays * sizeof(float) + sizeof(int32_t));
    static void write(const Vrl& vrl, const Scene& scene, float* const arrays[kArrays], int32_t* media, size_t k);
    static KernelVrls view(const float* const arrays[kArrays], const int32_t* media);

private:
    size_t size_ = 0, padded_ = 0;
    std::vector<float> floats_;  // kArrays arrays of padded_ floats
    std::vector<int32_t> media_;
};

}  // namespace vrl
