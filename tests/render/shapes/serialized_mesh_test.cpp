// Tests of loadSerializedMesh: small .serialized files written here with zlib (versions 3
// and 4, float and double, with and without normals, texcoords and colours, several shapes,
// no offset table), every rejected input (missing file, bad format id, wrong version, shape
// index out of range, corrupt and truncated zlib data, counts that do not fit, indices out
// of range, NaN positions), and the real bidir.serialized of the veach-lamp scene.
#include "render/shapes/serialized_mesh.h"

#include <gtest/gtest.h>
#include <zlib.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace vrl {
namespace {

using Bytes = std::vector<uint8_t>;

void putU16(Bytes& b, uint16_t v) {
    for (int i = 0; i < 2; ++i) b.push_back(uint8_t(v >> (8 * i)));
}
void putU32(Bytes& b, uint32_t v) {
    for (int i = 0; i < 4; ++i) b.push_back(uint8_t(v >> (8 * i)));
}
void putU64(Bytes& b, uint64_t v) {
    for (int i = 0; i < 8; ++i) b.push_back(uint8_t(v >> (8 * i)));
}
void putScalar(Bytes& b, double v, bool doublePrecision) {
    if (doublePrecision) {
        uint64_t bits;
        std::memcpy(&bits, &v, 8);
        putU64(b, bits);
    } else {
        const float f = float(v);
        uint32_t bits;
        std::memcpy(&bits, &f, 4);
        putU32(b, bits);
    }
}

// One shape as the writer lays it out; counts default to the array sizes.
struct TestShape {
    std::string name = "quad";
    std::vector<double> positions{0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    std::vector<double> normals, texcoords, colors;
    std::vector<uint32_t> indices{0, 1, 2, 0, 2, 3};
    bool doublePrecision = false;
    uint32_t extraFlags = 0;
    int64_t vertexCount = -1, triangleCount = -1;  // overrides
};

Bytes payload(const TestShape& s, uint16_t version) {
    Bytes b;
    uint32_t flags = s.doublePrecision ? 0x2000 : 0x1000;
    if (!s.normals.empty()) flags |= 0x0001;
    if (!s.texcoords.empty()) flags |= 0x0002;
    if (!s.colors.empty()) flags |= 0x0008;
    putU32(b, flags | s.extraFlags);
    if (version == 4) {
        b.insert(b.end(), s.name.begin(), s.name.end());
        b.push_back(0);
    }
    putU64(b, s.vertexCount >= 0 ? uint64_t(s.vertexCount) : s.positions.size() / 3);
    putU64(b, s.triangleCount >= 0 ? uint64_t(s.triangleCount) : s.indices.size() / 3);
    for (const auto* array : {&s.positions, &s.normals, &s.texcoords, &s.colors})
        for (double v : *array) putScalar(b, v, s.doublePrecision);
    for (uint32_t i : s.indices) putU32(b, i);
    return b;
}

Bytes deflate(const Bytes& data) {
    uLongf size = compressBound(uLong(data.size()));
    Bytes out(size);
    EXPECT_EQ(compress2(out.data(), &size, data.data(), uLong(data.size()), Z_BEST_COMPRESSION), Z_OK);
    out.resize(size);
    return out;
}

struct FileOptions {
    uint16_t formatId = 0x041C;
    uint16_t version = 4;
    bool offsetTable = true;
    size_t truncateStreamBy = 0;  // bytes cut from the end of every compressed stream
    bool breakZlibHeader = false;
};

Bytes serializedFile(const std::vector<TestShape>& shapes, const FileOptions& o = {}) {
    Bytes file;
    std::vector<uint64_t> offsets;
    for (const TestShape& s : shapes) {
        offsets.push_back(file.size());
        putU16(file, o.formatId);
        putU16(file, o.version);
        Bytes z = deflate(payload(s, o.version));
        z.resize(z.size() - o.truncateStreamBy);
        if (o.breakZlibHeader) z[0] = 0x00;
        file.insert(file.end(), z.begin(), z.end());
    }
    if (o.offsetTable) {
        for (uint64_t offset : offsets) o.version == 4 ? putU64(file, offset) : putU32(file, uint32_t(offset));
        putU32(file, uint32_t(shapes.size()));
    }
    return file;
}

std::filesystem::path writeFile(const std::string& name, const Bytes& bytes) {
    const auto dir = std::filesystem::path(testing::TempDir()) / "serialized_mesh_test";
    std::filesystem::create_directories(dir);
    std::ofstream(dir / name, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()),
                                                      std::streamsize(bytes.size()));
    return dir / name;
}

void expectLoadError(const std::filesystem::path& file, int index, const std::string& fragment) {
    try {
        loadSerializedMesh(file, index);
        ADD_FAILURE() << "no error loading shape " << index << " of " << file;
    } catch (const std::runtime_error& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find(file.filename().string()), std::string::npos) << message;
        EXPECT_NE(message.find(fragment), std::string::npos) << message;
    }
}

TEST(SerializedMeshTest, Version4FloatWithNormalsAndTexcoords) {
    TestShape s;
    s.normals = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
    s.texcoords = {0, 0, 1, 0, 1, 1, 0, 1};
    const auto file = writeFile("v4-float.serialized", serializedFile({s}));
    EXPECT_EQ(serializedShapeCount(file), 1);
    const TriangleMesh m = loadSerializedMesh(file, 0);
    ASSERT_EQ(m.positions.size(), 4u);
    EXPECT_EQ(m.positions[2], Vec3(1, 1, 0));
    ASSERT_EQ(m.normals.size(), 4u);
    EXPECT_EQ(m.normals[3], Vec3(0, 0, 1));
    ASSERT_EQ(m.texcoords.size(), 4u);
    EXPECT_EQ(m.texcoords[1], Vec2(1, 0));
    ASSERT_EQ(m.triangles.size(), 2u);
    EXPECT_EQ(m.triangles[1], (std::array<uint32_t, 3>{0, 2, 3}));
}

TEST(SerializedMeshTest, Version3DoubleWithoutAttributes) {
    TestShape s;
    s.doublePrecision = true;
    s.positions = {0.1, -2.5, 1e-3, 3, 4, 5, -1, 0, 2};
    s.indices = {0, 1, 2};
    FileOptions options;
    options.version = 3;
    const TriangleMesh m = loadSerializedMesh(writeFile("v3-double.serialized", serializedFile({s}, options)), 0);
    ASSERT_EQ(m.positions.size(), 3u);
    EXPECT_EQ(m.positions[0], Vec3(0.1f, -2.5f, 1e-3f));
    EXPECT_TRUE(m.normals.empty());
    EXPECT_TRUE(m.texcoords.empty());
    EXPECT_EQ(m.triangles.size(), 1u);
}

TEST(SerializedMeshTest, ColoursAreSkippedAndTheFaceNormalFlagIgnored) {
    TestShape s;
    s.doublePrecision = true;
    s.colors = {1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1};
    s.texcoords = {0, 0, 1, 0, 1, 1, 0, 1};
    s.extraFlags = 0x0010;
    const TriangleMesh m = loadSerializedMesh(writeFile("colours.serialized", serializedFile({s})), 0);
    EXPECT_EQ(m.texcoords[2], Vec2(1, 1));
    EXPECT_EQ(m.triangles[0], (std::array<uint32_t, 3>{0, 1, 2}));
}

TEST(SerializedMeshTest, SeveralShapesInOneFile) {
    for (const uint16_t version : {uint16_t(3), uint16_t(4)}) {
        TestShape triangle;
        triangle.name = "triangle";
        triangle.positions = {5, 5, 5, 6, 5, 5, 5, 6, 5};
        triangle.indices = {0, 1, 2};
        TestShape quad;
        quad.normals = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
        FileOptions options;
        options.version = version;
        const auto file = writeFile("two-v" + std::to_string(version) + ".serialized",
                                    serializedFile({triangle, quad, triangle}, options));
        EXPECT_EQ(serializedShapeCount(file), 3);
        const TriangleMesh first = loadSerializedMesh(file, 0), second = loadSerializedMesh(file, 1),
                           third = loadSerializedMesh(file, 2);
        EXPECT_EQ(first.triangles.size(), 1u);
        EXPECT_EQ(first.positions[1], Vec3(6, 5, 5));
        EXPECT_EQ(second.triangles.size(), 2u);
        EXPECT_EQ(second.normals.size(), 4u);
        EXPECT_EQ(third.positions, first.positions);
        expectLoadError(file, 3, "the file holds 3 shapes (indices 0..2)");
        expectLoadError(file, -1, "negative");
    }
}

TEST(SerializedMeshTest, FileWithoutOffsetTableHoldsOneShape) {
    FileOptions options;
    options.offsetTable = false;
    const auto file = writeFile("no-table.serialized", serializedFile({TestShape{}}, options));
    EXPECT_EQ(serializedShapeCount(file), 1);
    EXPECT_EQ(loadSerializedMesh(file, 0).triangles.size(), 2u);
    expectLoadError(file, 1, "no shape offset table");
}

TEST(SerializedMeshTest, BadFilesAndHeaders) {
    expectLoadError(std::filesystem::path(testing::TempDir()) / "no-such-mesh.serialized", 0, "does not exist");
    FileOptions options;
    options.formatId = 0x1234;
    expectLoadError(writeFile("bad-id.serialized", serializedFile({TestShape{}}, options)), 0, "format id 0x1234");
    options.formatId = 0x1C04;
    expectLoadError(writeFile("old-id.serialized", serializedFile({TestShape{}}, options)), 0, "older than 0.4");
    options = {};
    options.version = 5;
    expectLoadError(writeFile("v5.serialized", serializedFile({TestShape{}}, options)), 0, "version 5");
    expectLoadError(writeFile("tiny.serialized", Bytes{0x1C, 0x04}), 0, "too short");
}

TEST(SerializedMeshTest, CorruptAndTruncatedStreams) {
    FileOptions options;
    options.breakZlibHeader = true;
    expectLoadError(writeFile("corrupt.serialized", serializedFile({TestShape{}}, options)), 0, "corrupt zlib data");
    options = {};
    options.truncateStreamBy = 10;
    const auto truncated = writeFile("truncated.serialized", serializedFile({TestShape{}, TestShape{}}, options));
    expectLoadError(truncated, 0, "truncated zlib data");
    expectLoadError(truncated, 1, "truncated zlib data");
    // A file cut short loses its table: shape 0 is then read up to the end of the file.
    Bytes cut = serializedFile({TestShape{}});
    cut.resize(cut.size() / 2);
    expectLoadError(writeFile("cut.serialized", cut), 0, "truncated zlib data");
}

TEST(SerializedMeshTest, CountsThatDoNotFitTheData) {
    TestShape absurd;
    absurd.vertexCount = int64_t(1) << 30;  // would need 12 GiB
    expectLoadError(writeFile("absurd.serialized", serializedFile({absurd})), 0, "counts do not fit the data");
    absurd.vertexCount = int64_t(1) << 33;
    expectLoadError(writeFile("absurd-64.serialized", serializedFile({absurd})), 0, "more than 32-bit indices");
    TestShape hugeTriangles;
    hugeTriangles.triangleCount = std::numeric_limits<int64_t>::max();
    expectLoadError(writeFile("absurd-t.serialized", serializedFile({hugeTriangles})), 0, "do not fit");
    TestShape oneMore;
    oneMore.triangleCount = 3;  // plausible, but the stream ends after two
    expectLoadError(writeFile("one-more.serialized", serializedFile({oneMore})), 0, "ends early");
    TestShape empty;
    empty.indices.clear();
    expectLoadError(writeFile("empty.serialized", serializedFile({empty})), 0, "is empty");
    TestShape bothPrecisions;
    bothPrecisions.extraFlags = 0x2000;
    expectLoadError(writeFile("both.serialized", serializedFile({bothPrecisions})), 0, "double precision flag");
}

TEST(SerializedMeshTest, BadIndicesAndPositions) {
    TestShape badIndex;
    badIndex.indices = {0, 1, 2, 0, 2, 7};
    expectLoadError(writeFile("bad-index.serialized", serializedFile({badIndex})), 0,
                    "triangle 1 refers to vertex 7, but the shape has 4 vertices");
    TestShape nan;
    nan.positions[4] = std::nan("");
    expectLoadError(writeFile("nan.serialized", serializedFile({nan})), 0, "vertex 1 has a non-finite position");
    TestShape tooLarge;  // finite in double, infinite as float
    tooLarge.doublePrecision = true;
    tooLarge.positions[0] = 1e300;
    expectLoadError(writeFile("huge.serialized", serializedFile({tooLarge})), 0, "vertex 0 has a non-finite");
}

TEST(SerializedMeshTest, VeachLampSceneMeshes) {
    const auto file = std::filesystem::path(VRL_SHARED_SCENES_DIR) / "veach-lamp-mitsuba-bidir" / "bidir.serialized";
    if (!std::filesystem::exists(file)) GTEST_SKIP() << file << " is absent";
    ASSERT_EQ(serializedShapeCount(file), 11);
    // Vertex and triangle counts of its 11 shapes (egg, lamp exterior, cylinders, room, ...).
    const size_t vertices[] = {1083, 79, 96, 64, 128, 165, 4, 4, 391, 160, 26};
    const size_t triangles[] = {2162, 70, 64, 64, 128, 98, 2, 2, 630, 160, 12};
    for (int i = 0; i < 11; ++i) {
        SCOPED_TRACE("shape " + std::to_string(i));
        const TriangleMesh m = loadSerializedMesh(file, i);
        EXPECT_EQ(m.positions.size(), vertices[i]);
        EXPECT_EQ(m.triangles.size(), triangles[i]);
        EXPECT_EQ(m.normals.size(), m.positions.size());
        double area = 0.0;
        for (size_t t = 0; t < m.triangles.size(); ++t) area += m.triangleArea(t);
        EXPECT_GT(area, 0.0);
        for (const Vec3& p : m.positions) ASSERT_LT(p.length(), 200.0f);
    }
    expectLoadError(file, 11, "holds 11 shapes");
}

}  // namespace
}  // namespace vrl
