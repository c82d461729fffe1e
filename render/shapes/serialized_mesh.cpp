#include "render/shapes/serialized_mesh.h"

#include <zlib.h>

#include <algorithm>
#include <array>
#include <bit>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace vrl {
namespace {

constexpr uint16_t kFormatId = 0x041C;
constexpr uint16_t kOldFormatId = 0x1C04;  // files of Mitsuba before 0.4 (big endian)
constexpr uint16_t kVersion3 = 3, kVersion4 = 4;

constexpr uint32_t kHasNormals = 0x0001;
constexpr uint32_t kHasTexcoords = 0x0002;
constexpr uint32_t kHasColors = 0x0008;
constexpr uint32_t kSinglePrecision = 0x1000;
constexpr uint32_t kDoublePrecision = 0x2000;

// Deflate cannot compress better than 1032:1; more claimed data than that is corrupt.
constexpr uint64_t kMaxDeflateRatio = 1032;
constexpr size_t kMaxNameLength = 1 << 16;

uint32_t readU16(const uint8_t* p) { return uint32_t(p[0]) | uint32_t(p[1]) << 8; }
uint32_t readU32(const uint8_t* p) { return readU16(p) | readU16(p + 2) << 16; }
uint64_t readU64(const uint8_t* p) { return uint64_t(readU32(p)) | uint64_t(readU32(p + 4)) << 32; }

// Errors name the file; messages read "<file>: <problem>".
class MeshFile {
public:
    explicit MeshFile(const std::filesystem::path& path) : path_(path) {
        std::error_code error;
        if (!std::filesystem::exists(path, error)) fail("the file does not exist");
        if (!std::filesystem::is_regular_file(path, error)) fail("not a regular file");
        size_ = std::filesystem::file_size(path, error);
        if (error) fail("cannot determine the file size: " + error.message());
        stream_.open(path, std::ios::binary);
        if (!stream_) fail("cannot open the file for reading");
    }

    [[noreturn]] void fail(const std::string& problem) const {
        throw std::runtime_error(path_.string() + ": " + problem);
    }

    uint64_t size() const { return size_; }

    std::vector<uint8_t> read(uint64_t offset, uint64_t count) {
        if (offset > size_ || count > size_ - offset) fail("read past the end of the file (corrupt offsets?)");
        std::vector<uint8_t> bytes(count);
        stream_.clear();
        stream_.seekg(std::streamoff(offset));
        stream_.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(count));
        if (!stream_) fail("read error at byte " + std::to_string(offset));
        return bytes;
    }

    // The format id and version of the header at `offset`.
    uint16_t readHeader(uint64_t offset) {
        if (size_ < offset + 4) fail("too short to hold a .serialized header at byte " + std::to_string(offset));
        const auto header = read(offset, 4);
        const uint32_t format = readU16(header.data()), version = readU16(header.data() + 2);
        if (format == kOldFormatId)
            fail("written by a Mitsuba older than 0.4 (format id 0x1C04); re-export it with a current Mitsuba");
        if (format != kFormatId) {
            char hex[8];
            std::snprintf(hex, sizeof hex, "%04X", unsigned(format));
            fail(std::string("not a Mitsuba .serialized mesh: format id 0x") + hex + " at byte " +
                 std::to_string(offset) + ", expected 0x041C");
        }
        if (version != kVersion3 && version != kVersion4)
            fail("unsupported .serialized version " + std::to_string(version) + " (supported: 3 and 4)");
        return uint16_t(version);
    }

    // Shape start offsets from the table at the end of the file, or nothing when the end
    // does not hold a consistent table (Mitsuba then assumes one shape at offset 0).
    std::optional<std::vector<uint64_t>> readOffsetTable(uint16_t version) {
        if (size_ < 8) return std::nullopt;
        const uint64_t count = readU32(read(size_ - 4, 4).data());
        const uint64_t entry = version == kVersion4 ? 8 : 4;
        // Each shape needs at least a header, a minimal zlib stream and a table entry.
        if (count == 0 || count > (size_ - 4) / (entry + 4 + 8)) return std::nullopt;
        const uint64_t tableStart = size_ - 4 - count * entry;
        const auto table = read(tableStart, count * entry);
        std::vector<uint64_t> offsets(count);
        for (uint64_t i = 0; i < count; ++i)
            offsets[i] = entry == 8 ? readU64(&table[i * 8]) : readU32(&table[i * 4]);
        if (offsets[0] != 0) return std::nullopt;
        for (uint64_t i = 0; i < count; ++i) {
            // Increasing, inside the data, each with room for a header and some zlib data.
            const uint64_t end = i + 1 < count ? offsets[i + 1] : tableStart;
            if (offsets[i] > tableStart || end > tableStart || end < offsets[i] + 4 + 2) return std::nullopt;
        }
        tableStart_ = tableStart;
        return offsets;
    }

    uint64_t tableStart() const { return tableStart_; }

private:
    std::filesystem::path path_;
    std::ifstream stream_;
    uint64_t size_ = 0;
    uint64_t tableStart_ = 0;
};

// Sequential reads from one zlib stream, straight into the caller's memory.
class ZlibReader {
public:
    ZlibReader(std::vector<uint8_t> compressed, const MeshFile& file, std::string what)
        : input_(std::move(compressed)), file_(file), what_(std::move(what)) {
        if (inflateInit(&z_) != Z_OK) file_.fail(what_ + ": cannot initialise zlib");
        z_.next_in = input_.data();
        z_.avail_in = uInt(std::min<size_t>(input_.size(), UINT_MAX));
        fed_ = z_.avail_in;
    }
    ~ZlibReader() { inflateEnd(&z_); }
    ZlibReader(const ZlibReader&) = delete;
    ZlibReader& operator=(const ZlibReader&) = delete;

    void read(void* destination, size_t count, const char* field) {
        auto* out = static_cast<uint8_t*>(destination);
        while (count > 0) {
            const size_t chunk = std::min<size_t>(count, UINT_MAX);
            z_.next_out = out;
            z_.avail_out = uInt(chunk);
            while (z_.avail_out > 0) {
                if (z_.avail_in == 0 && fed_ < input_.size()) {
                    z_.avail_in = uInt(std::min<size_t>(input_.size() - fed_, UINT_MAX));
                    fed_ += z_.avail_in;
                }
                if (ended_) fail(field, "the data ends early: the counts in the header do not fit the data");
                const int status = inflate(&z_, Z_NO_FLUSH);
                if (status == Z_STREAM_END) {
                    ended_ = true;
                } else if (status == Z_BUF_ERROR && z_.avail_in == 0) {
                    fail(field, "truncated zlib data (the compressed stream ends early)");
                } else if (status != Z_OK) {
                    fail(field, std::string("corrupt zlib data (") + (z_.msg ? z_.msg : zError(status)) + ")");
                }
            }
            out += chunk;
            count -= chunk;
        }
    }

    [[noreturn]] void fail(const char* field, const std::string& problem) const {
        file_.fail(what_ + ", reading " + field + ": " + problem);
    }

private:
    std::vector<uint8_t> input_;
    size_t fed_ = 0;
    const MeshFile& file_;
    std::string what_;
    z_stream z_{};
    bool ended_ = false;
};

// Reads `count` tuples of `N` scalars (float or double) and hands each, as floats, to `use`.
template <int N, typename Use>
void readTuples(ZlibReader& in, uint64_t count, bool doublePrecision, const char* field, Use use) {
    const size_t scalar = doublePrecision ? 8 : 4;
    constexpr uint64_t kBlock = 4096;
    std::vector<uint8_t> block(kBlock * N * scalar);
    for (uint64_t first = 0; first < count; first += kBlock) {
        const uint64_t n = std::min(kBlock, count - first);
        in.read(block.data(), n * N * scalar, field);
        for (uint64_t i = 0; i < n; ++i) {
            std::array<float, N> tuple;
            for (int k = 0; k < N; ++k) {
                const uint8_t* p = &block[(i * N + k) * scalar];
                tuple[k] = doublePrecision ? float(std::bit_cast<double>(readU64(p))) : std::bit_cast<float>(readU32(p));
            }
            use(first + i, tuple);
        }
    }
}

struct ShapeLocation {
    uint64_t offset = 0;  // of the shape's header
    uint64_t end = 0;     // one past its compressed data
    uint64_t count = 1;   // shapes in the file
};

ShapeLocation locateShape(MeshFile& file, uint16_t version, int shapeIndex) {
    const auto offsets = file.readOffsetTable(version);
    ShapeLocation where;
    if (!offsets) {
        if (shapeIndex != 0)
            file.fail("shape index " + std::to_string(shapeIndex) +
                      " is out of range: the file has no shape offset table, so it holds one shape (index 0)");
        where.end = file.size();
        return where;
    }
    where.count = offsets->size();
    if (shapeIndex < 0 || uint64_t(shapeIndex) >= where.count)
        file.fail("shape index " + std::to_string(shapeIndex) + " is out of range: the file holds " +
                  std::to_string(where.count) + " shape" + (where.count == 1 ? "" : "s") + " (indices 0.." +
                  std::to_string(where.count - 1) + ")");
    where.offset = (*offsets)[shapeIndex];
    where.end = uint64_t(shapeIndex) + 1 < where.count ? (*offsets)[shapeIndex + 1] : file.tableStart();
    return where;
}

}  // namespace

int serializedShapeCount(const std::filesystem::path& path) {
    MeshFile file(path);
    const uint16_t version = file.readHeader(0);
    const auto offsets = file.readOffsetTable(version);
    return offsets ? int(std::min<size_t>(offsets->size(), INT_MAX)) : 1;
}

TriangleMesh loadSerializedMesh(const std::filesystem::path& path, int shapeIndex) {
    MeshFile file(path);
    if (shapeIndex < 0) file.fail("shape index " + std::to_string(shapeIndex) + " is negative");
    const ShapeLocation where = locateShape(file, file.readHeader(0), shapeIndex);
    const uint16_t version = file.readHeader(where.offset);
    const std::string what = "shape " + std::to_string(shapeIndex);
    const uint64_t compressedSize = where.end - where.offset - 4;
    ZlibReader in(file.read(where.offset + 4, compressedSize), file, what);

    uint8_t word[8];
    in.read(word, 4, "the flags");
    const uint32_t flags = readU32(word);
    if ((flags & kSinglePrecision) && (flags & kDoublePrecision))
        in.fail("the flags", "both the single and the double precision flag are set");
    const bool doublePrecision = (flags & kDoublePrecision) != 0;
    std::string name;
    if (version == kVersion4) {
        for (char c = 0;; name.push_back(c)) {
            in.read(&c, 1, "the shape name");
            if (c == '\0') break;
            if (name.size() >= kMaxNameLength) in.fail("the shape name", "not null-terminated within 64 KiB");
        }
    }
    const std::string label = name.empty() ? what : what + " ('" + name + "')";
    in.read(word, 8, "the vertex count");
    const uint64_t vertexCount = readU64(word);
    in.read(word, 8, "the triangle count");
    const uint64_t triangleCount = readU64(word);
    if (vertexCount == 0 || triangleCount == 0)
        file.fail(label + " is empty (" + std::to_string(vertexCount) + " vertices, " + std::to_string(triangleCount) +
                  " triangles)");
    if (vertexCount > UINT32_MAX)
        file.fail(label + " has " + std::to_string(vertexCount) + " vertices, more than 32-bit indices can address");

    // Before allocating anything: could the compressed bytes hold what the counts claim?
    const uint64_t scalars = 3 + ((flags & kHasNormals) ? 3 : 0) + ((flags & kHasTexcoords) ? 2 : 0) +
                             ((flags & kHasColors) ? 3 : 0);
    const uint64_t bytesPerVertex = scalars * (doublePrecision ? 8 : 4);
    const uint64_t capacity = compressedSize < (uint64_t(1) << 48) ? kMaxDeflateRatio * compressedSize + 1024
                                                                    : UINT64_MAX / 2;
    if (vertexCount > capacity / bytesPerVertex || triangleCount > capacity / 12 ||
        vertexCount * bytesPerVertex + triangleCount * 12 > capacity)
        file.fail(label + " claims " + std::to_string(vertexCount) + " vertices and " + std::to_string(triangleCount) +
                  " triangles, more than its " + std::to_string(compressedSize) +
                  " compressed bytes can hold: the counts do not fit the data");

    // Arrays grow as data arrives, so memory follows the real data, not the claimed counts.
    constexpr uint64_t kReserveLimit = 1 << 20;
    TriangleMesh mesh;
    mesh.positions.reserve(std::min(vertexCount, kReserveLimit));
    readTuples<3>(in, vertexCount, doublePrecision, "the positions", [&](uint64_t i, const std::array<float, 3>& p) {
        if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
            file.fail(label + ": vertex " + std::to_string(i) + " has a non-finite position (NaN or infinite)");
        mesh.positions.emplace_back(p[0], p[1], p[2]);
    });
    if (flags & kHasNormals) {
        mesh.normals.reserve(mesh.positions.size());
        readTuples<3>(in, vertexCount, doublePrecision, "the normals",
                      [&](uint64_t, const std::array<float, 3>& n) { mesh.normals.emplace_back(n[0], n[1], n[2]); });
    }
    if (flags & kHasTexcoords) {
        mesh.texcoords.reserve(mesh.positions.size());
        readTuples<2>(in, vertexCount, doublePrecision, "the texture coordinates",
                      [&](uint64_t, const std::array<float, 2>& uv) { mesh.texcoords.emplace_back(uv[0], uv[1]); });
    }
    if (flags & kHasColors)
        readTuples<3>(in, vertexCount, doublePrecision, "the vertex colours", [](uint64_t, const std::array<float, 3>&) {});

    mesh.triangles.reserve(std::min(triangleCount, kReserveLimit));
    constexpr uint64_t kBlock = 4096;
    std::vector<uint8_t> block(kBlock * 12);
    for (uint64_t first = 0; first < triangleCount; first += kBlock) {
        const uint64_t n = std::min(kBlock, triangleCount - first);
        in.read(block.data(), n * 12, "the triangles");
        for (uint64_t t = 0; t < n; ++t) {
            std::array<uint32_t, 3> triangle;
            for (int k = 0; k < 3; ++k) {
                triangle[k] = readU32(&block[t * 12 + k * 4]);
                if (triangle[k] >= vertexCount)
                    file.fail(label + ": triangle " + std::to_string(first + t) + " refers to vertex " +
                              std::to_string(triangle[k]) + ", but the shape has " + std::to_string(vertexCount) +
                              " vertices");
            }
            mesh.triangles.push_back(triangle);
        }
    }
    return mesh;
}

}  // namespace vrl
