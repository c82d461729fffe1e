// Writes the binary seed inputs of the light_tree and scene_bundle fuzzers:
//   make_seeds OUT_DIR  ->  OUT_DIR/light_tree/*.bin, OUT_DIR/scene_bundle/*.pb
// Built by the fuzz build only (target vrl_fuzz_make_seeds); its output is
// committed under fuzz/corpus/, so this is run by hand when a format changes.
#include "render/lightcuts/tree/light_tree.h"
#include "render/lightcuts/tree/light_tree_io.h"
#include "service/job/scene_bundle.h"

#include <zlib.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

void writeFile(const fs::path& path, const void* data, size_t size) {
    fs::create_directories(path.parent_path());
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(static_cast<const char*>(data), std::streamsize(size));
    if (!out) throw std::runtime_error("cannot write " + path.string());
}
void writeFile(const fs::path& path, const std::vector<uint8_t>& bytes) { writeFile(path, bytes.data(), bytes.size()); }
void writeFile(const fs::path& path, const std::string& text) { writeFile(path, text.data(), text.size()); }

std::vector<vrl::Vrl> someVrls(int count, int media) {
    std::vector<vrl::Vrl> vrls;
    for (int i = 0; i < count; ++i) {
        vrl::Vrl v;
        v.origin = {0.1f * i, 0.5f - 0.05f * i, 0.25f * (i % 3)};
        const float a = 0.7f * i;
        v.direction = {std::cos(a), std::sin(a), 0.0f};
        v.length = 0.2f + 0.1f * i;
        v.flux = {1.0f + i, 0.5f, 0.25f * i};
        v.medium = media > 0 ? i % media : -1;
        vrls.push_back(v);
    }
    return vrls;
}

void put32(std::vector<uint8_t>& out, uint32_t v) {
    for (int i = 0; i < 4; ++i) out.push_back(uint8_t(v >> (8 * i)));
}
void put64(std::vector<uint8_t>& out, uint64_t v) {
    for (int i = 0; i < 8; ++i) out.push_back(uint8_t(v >> (8 * i)));
}
void putFloat(std::vector<uint8_t>& out, float f) {
    uint32_t bits;
    std::memcpy(&bits, &f, 4);
    put32(out, bits);
}

// A Mitsuba .serialized file (version 4, single precision) holding a tetrahedron.
std::vector<uint8_t> serializedTetrahedron() {
    std::vector<uint8_t> raw;
    put32(raw, 0x1000 | 0x0002);  // single precision, texcoords
    for (char c : std::string("tet")) raw.push_back(uint8_t(c));
    raw.push_back(0);
    put64(raw, 4);
    put64(raw, 4);
    const float p[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (const auto& v : p)
        for (float f : v) putFloat(raw, f);
    const float uv[4][2] = {{0, 0}, {1, 0}, {0, 1}, {1, 1}};
    for (const auto& t : uv)
        for (float f : t) putFloat(raw, f);
    const uint32_t tri[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
    for (const auto& t : tri)
        for (uint32_t i : t) put32(raw, i);
    std::vector<uint8_t> compressed(compressBound(uLong(raw.size())));
    uLongf length = uLongf(compressed.size());
    if (compress2(compressed.data(), &length, raw.data(), uLong(raw.size()), 9) != Z_OK)
        throw std::runtime_error("zlib failed");
    compressed.resize(length);
    std::vector<uint8_t> file = {0x1C, 0x04, 0x04, 0x00};
    file.insert(file.end(), compressed.begin(), compressed.end());
    put64(file, 0);  // offset table: one shape at 0
    put32(file, 1);
    return file;
}

const char* kSceneHead = R"(<scene version="0.5.0">
  <integrator type="volpath"><integer name="maxDepth" value="4"/></integrator>
  <sensor type="perspective">
    <float name="fov" value="45"/>
    <transform name="toWorld"><lookat origin="0, 0, -4" target="0, 0, 0" up="0, 1, 0"/></transform>
    <sampler type="independent"><integer name="sampleCount" value="4"/></sampler>
    <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="12"/></film>
  </sensor>
  <emitter type="point"><point name="position" x="0" y="2" z="-1"/><rgb name="intensity" value="5"/></emitter>
)";

}  // namespace

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: %s OUT_DIR\n", argv[0]);
        return 2;
    }
    const fs::path out = argv[1];

    // Light trees and VRL sets.
    const int sizes[] = {0, 1, 2, 5};
    for (int n : sizes) {
        const auto tree = vrl::LightTree::build(someVrls(n, n > 2 ? 2 : 0));
        writeFile(out / "light_tree" / ("tree-" + std::to_string(n) + ".bin"), vrl::serializeLightTree(tree));
        vrl::VrlSet set;
        set.vrls = someVrls(n, 1);
        set.lightPaths = 1000 + n;
        writeFile(out / "light_tree" / ("set-" + std::to_string(n) + ".bin"), vrl::serializeVrlSet(set));
    }

    // Bundles, built from files in a scratch directory.
    const fs::path scratch = fs::temp_directory_path() / "vrl-make-seeds";
    fs::remove_all(scratch);
    const auto bundle = [&](const std::string& name, const std::string& sceneText,
                            const std::vector<std::pair<std::string, std::vector<uint8_t>>>& extra) {
        const fs::path dir = scratch / name;
        writeFile(dir / "scene.xml", sceneText);
        std::vector<fs::path> files{dir / "scene.xml"};
        for (const auto& [path, bytes] : extra) {
            writeFile(dir / path, bytes);
            files.push_back(dir / path);
        }
        writeFile(out / "scene_bundle" / (name + ".pb"), vrl::rpc::makeBundleBlob(dir / "scene.xml", files));
    };
    const auto bytes = [](const std::string& s) { return std::vector<uint8_t>(s.begin(), s.end()); };

    bundle("spheres", std::string(kSceneHead) + R"(
  <medium type="homogeneous" id="fog"><rgb name="sigmaS" value="0.5"/><rgb name="sigmaA" value="0.1"/>
    <phase type="hg"><float name="g" value="0.3"/></phase></medium>
  <shape type="sphere"><float name="radius" value="0.5"/><bsdf type="diffuse"/><ref name="interior" id="fog"/></shape>
  <shape type="rectangle"><transform name="toWorld"><scale value="3"/><translate y="-1"/></transform>
    <emitter type="area"><rgb name="radiance" value="1"/></emitter></shape>
</scene>
)", {});
    bundle("obj", std::string(kSceneHead) + R"(
  <shape type="obj"><string name="filename" value="meshes/quad.obj"/><bsdf type="roughplastic"/></shape>
</scene>
)", {{"meshes/quad.obj", bytes("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\n"
                                   "f 1/1/1 2/2/1 3/3/1 4/1/1\n")}});
    bundle("serialized", std::string(kSceneHead) + R"(
  <shape type="serialized"><string name="filename" value="tet.serialized"/><integer name="shapeIndex" value="0"/>
    <bsdf type="conductor"><string name="material" value="Au"/></bsdf></shape>
</scene>
)", {{"tet.serialized", serializedTetrahedron()}});
    bundle("include", std::string(kSceneHead) + R"(
  <include filename="parts/materials.xml"/>
  <shape type="cube"><ref id="white"/></shape>
</scene>
)", {{"parts/materials.xml", bytes("<scene version=\"0.5.0\"><bsdf type=\"diffuse\" id=\"white\">"
                                       "<rgb name=\"reflectance\" value=\"0.8\"/></bsdf></scene>\n")}});
    fs::remove_all(scratch);
    std::printf("seeds written under %s\n", out.c_str());
    return 0;
}
