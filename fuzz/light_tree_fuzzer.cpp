// libFuzzer target: the light-tree, VRL-set, surface-VPL and job-lights
// deserialisers (render/lightcuts/tree/light_tree_io.h).
//
// Every input is given to vrl::deserializeLightTree, vrl::deserializeVrlSet,
// vrl::deserializeSurfaceVpls and vrl::parseJobLights twice: as it is, and with its last four bytes replaced
// by the CRC-32 of the rest, so that mutations get past the checksum and reach
// the size checks and LightTree::fromParts. What deserialises must serialise
// back to the very same bytes (the documented bit-exact inverse); a difference
// aborts.
//
// Documented refusals: std::runtime_error (and std::invalid_argument for null
// data, which cannot happen here). Anything else is reported with
// VRL_FUZZ_STRICT_EXCEPTIONS=1 (fuzz_common.h).
#include "fuzz/fuzz_common.h"
#include "render/lightcuts/tree/light_tree_io.h"

#include <zlib.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <vector>

namespace {

void mustEqual(const std::vector<uint8_t>& reserialised, const uint8_t* data, size_t size, const char* what) {
    if (reserialised.size() != size || std::memcmp(reserialised.data(), data, size) != 0) {
        std::fprintf(stderr, "==vrl-fuzz== %s: deserialise + serialise is not the identity (%zu bytes in, %zu out)\n",
                     what, size, reserialised.size());
        std::abort();
    }
}

void check(const uint8_t* data, size_t size) {
    try {
        const vrl::LightTree tree = vrl::deserializeLightTree(data, size);
        mustEqual(vrl::serializeLightTree(tree), data, size, "light tree");
        vrl_fuzz::accepted("light tree");
    } catch (const std::runtime_error& e) {
        vrl_fuzz::refused("deserializeLightTree", e);
    } catch (const std::exception& e) {
        if (vrl_fuzz::strictExceptions()) vrl_fuzz::undocumented("deserializeLightTree", e);
        vrl_fuzz::refused("deserializeLightTree", e);
    }
    try {
        const vrl::SurfaceVplLights lights = vrl::deserializeSurfaceVpls(data, size);
        mustEqual(vrl::serializeSurfaceVpls(lights), data, size, "surface VPLs");
        vrl_fuzz::accepted("surface VPLs");
    } catch (const std::runtime_error& e) {
        vrl_fuzz::refused("deserializeSurfaceVpls", e);
    } catch (const std::exception& e) {
        if (vrl_fuzz::strictExceptions()) vrl_fuzz::undocumented("deserializeSurfaceVpls", e);
        vrl_fuzz::refused("deserializeSurfaceVpls", e);
    }
    try {
        const vrl::JobLightsParts parts = vrl::parseJobLights(data, size);
        mustEqual(vrl::serializeJobLights(parts.primary, parts.surfaceVpls), data, size, "job lights");
        vrl_fuzz::accepted("job lights");
    } catch (const std::runtime_error& e) {
        vrl_fuzz::refused("parseJobLights", e);
    } catch (const std::exception& e) {
        if (vrl_fuzz::strictExceptions()) vrl_fuzz::undocumented("parseJobLights", e);
        vrl_fuzz::refused("parseJobLights", e);
    }
    try {
        const vrl::VrlSet set = vrl::deserializeVrlSet(data, size);
        mustEqual(vrl::serializeVrlSet(set), data, size, "VRL set");
        vrl_fuzz::accepted("VRL set");
    } catch (const std::runtime_error& e) {
        vrl_fuzz::refused("deserializeVrlSet", e);
    } catch (const std::exception& e) {
        if (vrl_fuzz::strictExceptions()) vrl_fuzz::undocumented("deserializeVrlSet", e);
        vrl_fuzz::refused("deserializeVrlSet", e);
    }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    vrl_fuzz::quietLogs();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    // An exact-size heap copy, so that ASan sees any read past the end.
    std::vector<uint8_t> blob(data, data + size);
    check(blob.data(), blob.size());
    if (blob.size() >= 4) {
        const size_t body = blob.size() - 4;
        const uint32_t crc = static_cast<uint32_t>(crc32_z(crc32_z(0L, Z_NULL, 0), blob.data(), body));
        for (int i = 0; i < 4; ++i) blob[body + i] = static_cast<uint8_t>(crc >> (8 * i));
        check(blob.data(), blob.size());
    }
    return 0;
}
