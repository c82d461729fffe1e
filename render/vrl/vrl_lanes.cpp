#include "render/vrl/vrl_lanes.h"

#include "render/scene/scene.h"

namespace vrl {

VrlLanes::VrlLanes(const std::vector<Vrl>& vrls, const Scene& scene)
    : size_(vrls.size()), padded_((vrls.size() + kKernelPadding - 1) / kKernelPadding * kKernelPadding) {
    floats_.assign(size_t(kArrays) * padded_, 0.0f);
    media_.assign(padded_, -1);
    float* arrays[kArrays];
    for (int a = 0; a < kArrays; ++a) arrays[a] = floats_.data() + size_t(a) * padded_;
    for (size_t k = 0; k < size_; ++k) write(vrls[k], scene, arrays, media_.data(), k);
}

void VrlLanes::write(const Vrl& v, const Scene& scene, float* const arrays[kArrays], int32_t* media, size_t k) {
    const HomogeneousMedium& medium = scene.media()[size_t(v.medium)];
    const Rgb flux = v.flux * medium.sigmaS();
    const float values[kArrays] = {v.origin.x,    v.origin.y,    v.origin.z, v.direction.x,
                                   v.direction.y, v.direction.z, v.length,   medium.phase().g(),
                                   flux.x,        flux.y,        flux.z};
    for (int a = 0; a < kArrays; ++a) arrays[a][k] = values[a];
    media[k] = v.medium;
}

KernelVrls VrlLanes::view(const float* const a[kArrays], const int32_t* media) {
    return {a[kOriginX], a[kOriginY], a[kOriginZ], a[kDirectionX], a[kDirectionY], a[kDirectionZ],
            a[kLength],  a[kG],       a[kFluxR],   a[kFluxG],      a[kFluxB],      media};
}

KernelVrls VrlLanes::from(size_t first) const {
    const float* arrays[kArrays];
    for (int a = 0; a < kArrays; ++a) arrays[a] = floats_.data() + size_t(a) * padded_ + first;
    return view(arrays, media_.data() + first);
}

}  // namespace vrl
