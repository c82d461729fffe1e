#include "render/lightcuts/tree/light_tree_io.h"

#include "util/hash.h"

#include <algorithm>
#include <span>
#include <bit>
#include <cstring>
#include <iterator>
#include <stdexcept>
#include <string>

namespace vrl {
namespace {

constexpr char kMagic[8] = {'V', 'R', 'L', 'T', 'R', 'E', 'E', '\0'};
constexpr char kTreesMagic[8] = {'V', 'R', 'L', 'T', 'R', 'E', 'E', 'S'};
constexpr size_t kTreesHeaderBytes = 8 + 2 * 4;  // magic, version, count
constexpr char kSetMagic[8] = {'V', 'R', 'L', 'S', 'E', 'T', '\0', '\0'};
constexpr size_t kSetHeaderBytes = 8 + 4 * 4;  // magic, version, count, light paths (2 x u32)
constexpr size_t kHeaderBytes = 8 + 4 * 4;  // magic, version, vrl count, node count, root
constexpr char kSurfaceMagic[8] = {'V', 'R', 'L', 'S', 'V', 'P', 'L', 'S'};
constexpr size_t kSurfaceHeaderBytes = 8 + 2 * 4;  // magic, version, count
constexpr size_t kSurfaceVplBytes = 21 * 4;
constexpr char kJobMagic[8] = {'V', 'R', 'L', 'L', 'I', 'G', 'H', 'T'};
constexpr size_t kJobHeaderBytes = 8 + 4 + 2 * 8;  // magic, version, primary size, surface size
constexpr size_t kVrlBytes = 11 * 4;
constexpr size_t kNodeBytes = 18 * 4;
constexpr size_t kCrcBytes = 4;

class Writer {
public:
    explicit Writer(size_t capacity) { bytes_.reserve(capacity); }
    void u32(uint32_t v) {
        for (int shift = 0; shift < 32; shift += 8) bytes_.push_back(static_cast<uint8_t>(v >> shift));
    }
    void i32(int32_t v) { u32(static_cast<uint32_t>(v)); }
    void u64(uint64_t v) {
        u32(static_cast<uint32_t>(v));
        u32(static_cast<uint32_t>(v >> 32));
    }
    void f32(float v) { u32(std::bit_cast<uint32_t>(v)); }
    void bytes(std::span<const uint8_t> b) { bytes_.insert(bytes_.end(), b.begin(), b.end()); }
    void v3(const Imath::V3f& v) {
        f32(v.x);
        f32(v.y);
        f32(v.z);
    }
    std::vector<uint8_t>& bytes() { return bytes_; }

private:
    std::vector<uint8_t> bytes_;
};

// Reads fields from a range whose size the caller has already checked; every
// read is still bounds-checked so a logic error cannot read past the end.
class Reader {
public:
    Reader(const uint8_t* data, size_t size) : data_(data), size_(size) {}
    uint32_t u32() {
        if (size_ - pos_ < 4) throw std::runtime_error("light tree blob: internal error, read past the end");
        uint32_t v = 0;
        for (int i = 0; i < 4; ++i) v |= uint32_t(data_[pos_ + i]) << (8 * i);
        pos_ += 4;
        return v;
    }
    uint64_t u64() {
        const uint64_t low = u32();
        return low | uint64_t(u32()) << 32;
    }
    int32_t i32() { return static_cast<int32_t>(u32()); }
    float f32() { return std::bit_cast<float>(u32()); }
    Imath::V3f v3() {
        Imath::V3f v;
        v.x = f32();
        v.y = f32();
        v.z = f32();
        return v;
    }

private:
    const uint8_t* data_;
    size_t size_;
    size_t pos_ = 0;
};

void writeVrl(Writer& out, const Vrl& v) {
    out.v3(v.origin);
    out.v3(v.direction);
    out.f32(v.length);
    out.v3(v.flux);
    out.i32(v.medium);
}

Vrl readVrl(Reader& in) {
    Vrl v;
    v.origin = in.v3();
    v.direction = in.v3();
    v.length = in.f32();
    v.flux = in.v3();
    v.medium = in.i32();
    return v;
}

void writeSurfaceVpl(Writer& out, const SurfaceVpl& v) {
    out.v3(v.position);
    out.v3(v.geometricNormal);
    out.v3(v.shadingNormal);
    out.f32(v.uv.x);
    out.f32(v.uv.y);
    out.u32(v.shape);
    out.u32(v.triangle);
    out.f32(v.scale);
    out.v3(v.direction);
    out.v3(v.flux);
    out.i32(v.medium);
}

SurfaceVpl readSurfaceVpl(Reader& in) {
    SurfaceVpl v;
    v.position = in.v3();
    v.geometricNormal = in.v3();
    v.shadingNormal = in.v3();
    v.uv.x = in.f32();
    v.uv.y = in.f32();
    v.shape = in.u32();
    v.triangle = in.u32();
    v.scale = in.f32();
    v.direction = in.v3();
    v.flux = in.v3();
    v.medium = in.i32();
    return v;
}

uint64_t blobBytes(uint64_t vrlCount, uint64_t nodeCount) {
    return kHeaderBytes + vrlCount * kVrlBytes + nodeCount * kNodeBytes + kCrcBytes;
}

}  // namespace

std::vector<uint8_t> serializeLightTree(const LightTree& tree) {
    const auto& vrls = tree.vrls();
    const auto& nodes = tree.nodes();
    if (vrls.size() > UINT32_MAX || nodes.size() > UINT32_MAX)
        throw std::invalid_argument("light tree too large to serialise (more than 2^32 - 1 VRLs or nodes)");
    Writer out(blobBytes(vrls.size(), nodes.size()));
    out.bytes().insert(out.bytes().end(), std::begin(kMagic), std::end(kMagic));
    out.u32(kLightTreeFormatVersion);
    out.u32(static_cast<uint32_t>(vrls.size()));
    out.u32(static_cast<uint32_t>(nodes.size()));
    out.i32(tree.root());
    for (const Vrl& v : vrls) writeVrl(out, v);
    for (const LightTreeNode& n : nodes) {
        out.v3(n.box.min);
        out.v3(n.box.max);
        out.v3(n.fluxLength);
        out.v3(n.clusterFlux);
        out.f32(n.maxLength);
        out.u32(n.representative);
        out.u32(n.vrlCount);
        out.i32(n.left);
        out.i32(n.right);
        out.i32(n.medium);
    }
    out.u32(util::crc32Of(out.bytes().data(), out.bytes().size()));
    return std::move(out.bytes());
}

LightTree deserializeLightTree(const uint8_t* data, size_t size) {
    if (size > 0 && data == nullptr) throw std::invalid_argument("deserializeLightTree: null data");
    // Magic first, over however many bytes there are, so a foreign file is named as such.
    const size_t magicBytes = std::min(size, sizeof kMagic);
    if (magicBytes > 0 && std::memcmp(data, kMagic, magicBytes) != 0)
        throw std::runtime_error("not a VRL light tree (the blob does not start with \"VRLTREE\")");
    if (size < kHeaderBytes + kCrcBytes)
        throw std::runtime_error("light tree blob is truncated: expected at least " +
                                 std::to_string(kHeaderBytes + kCrcBytes) + " bytes, found " + std::to_string(size));
    Reader header(data + sizeof kMagic, kHeaderBytes - sizeof kMagic);
    const uint32_t version = header.u32();
    if (version != kLightTreeFormatVersion)
        throw std::runtime_error("light tree blob has format version " + std::to_string(version) +
                                 " but this build reads version " + std::to_string(kLightTreeFormatVersion) +
                                 "; rebuild the tree with this version");
    const uint32_t vrlCount = header.u32();
    const uint32_t nodeCount = header.u32();
    const int32_t root = header.i32();
    const uint64_t expected = blobBytes(vrlCount, nodeCount);  // no overflow: < 2^39
    if (size != expected) {
        const std::string counts = "expected " + std::to_string(expected) + " bytes for the " +
                                   std::to_string(vrlCount) + " VRLs and " + std::to_string(nodeCount) +
                                   " nodes its header declares, found " + std::to_string(size) + " bytes";
        throw std::runtime_error(size < expected ? "light tree blob is truncated (or its header corrupt): " + counts
                                                 : "light tree blob is longer than expected (trailing data or a "
                                                   "corrupt header): " + counts);
    }
    const uint32_t storedCrc = Reader(data + size - kCrcBytes, kCrcBytes).u32();
    const uint32_t actualCrc = util::crc32Of(data, size - kCrcBytes);
    if (storedCrc != actualCrc)
        throw std::runtime_error("light tree blob is corrupt: checksum mismatch (stored CRC-32 " +
                                 std::to_string(storedCrc) + ", computed " + std::to_string(actualCrc) + ")");

    Reader in(data + kHeaderBytes, size - kHeaderBytes - kCrcBytes);
    std::vector<Vrl> vrls(vrlCount);  // sizes verified against the blob above
    for (Vrl& v : vrls) v = readVrl(in);
    std::vector<LightTreeNode> nodes(nodeCount);
    for (LightTreeNode& n : nodes) {
        n.box.min = in.v3();
        n.box.max = in.v3();
        n.fluxLength = in.v3();
        n.clusterFlux = in.v3();
        n.maxLength = in.f32();
        n.representative = in.u32();
        n.vrlCount = in.u32();
        n.left = in.i32();
        n.right = in.i32();
        n.medium = in.i32();
    }
    try {
        return LightTree::fromParts(std::move(vrls), std::move(nodes), root);
    } catch (const std::invalid_argument& e) {
        throw std::runtime_error(std::string("light tree blob holds a structurally invalid tree (checksum is valid, "
                                             "so it was written that way): ") + e.what());
    }
}

std::vector<uint8_t> serializeVrlSet(const VrlSet& set) {
    if (set.vrls.size() > UINT32_MAX) throw std::invalid_argument("VRL set too large to serialise (over 2^32 - 1)");
    Writer out(kSetHeaderBytes + set.vrls.size() * kVrlBytes + kCrcBytes);
    out.bytes().insert(out.bytes().end(), std::begin(kSetMagic), std::end(kSetMagic));
    out.u32(kLightTreeFormatVersion);
    out.u32(static_cast<uint32_t>(set.vrls.size()));
    out.u32(static_cast<uint32_t>(set.lightPaths));
    out.u32(static_cast<uint32_t>(set.lightPaths >> 32));
    for (const Vrl& v : set.vrls) writeVrl(out, v);
    out.u32(util::crc32Of(out.bytes().data(), out.bytes().size()));
    return std::move(out.bytes());
}

VrlSet deserializeVrlSet(const uint8_t* data, size_t size) {
    if (size > 0 && data == nullptr) throw std::invalid_argument("deserializeVrlSet: null data");
    if (size < kSetHeaderBytes + kCrcBytes || std::memcmp(data, kSetMagic, sizeof kSetMagic) != 0)
        throw std::runtime_error("not a VRL set blob (too short, or it does not start with \"VRLSET\")");
    Reader header(data + sizeof kSetMagic, kSetHeaderBytes - sizeof kSetMagic);
    const uint32_t version = header.u32();
    if (version != kLightTreeFormatVersion)
        throw std::runtime_error("VRL set blob has format version " + std::to_string(version) +
                                 " but this build reads version " + std::to_string(kLightTreeFormatVersion));
    const uint32_t count = header.u32();
    const uint64_t low = header.u32(), high = header.u32();
    const uint64_t expected = kSetHeaderBytes + uint64_t(count) * kVrlBytes + kCrcBytes;
    if (size != expected)
        throw std::runtime_error("VRL set blob has the wrong size: expected " + std::to_string(expected) +
                                 " bytes for " + std::to_string(count) + " VRLs, found " + std::to_string(size));
    const uint32_t storedCrc = Reader(data + size - kCrcBytes, kCrcBytes).u32();
    if (storedCrc != util::crc32Of(data, size - kCrcBytes))
        throw std::runtime_error("VRL set blob is corrupt: checksum mismatch");
    Reader in(data + kSetHeaderBytes, size - kSetHeaderBytes - kCrcBytes);
    VrlSet set;
    set.lightPaths = low | (high << 32);
    set.vrls.resize(count);
    for (Vrl& v : set.vrls) v = readVrl(in);
    return set;
}

std::vector<uint8_t> serializeLightTrees(const std::vector<const LightTree*>& trees) {
    if (trees.empty() || trees.size() > kMaxLightTreesInBlob)
        throw std::invalid_argument("serializeLightTrees: 1 ... " + std::to_string(kMaxLightTreesInBlob) +
                                    " trees, not " + std::to_string(trees.size()));
    std::vector<std::vector<uint8_t>> blobs;
    size_t total = kTreesHeaderBytes + 8 * trees.size() + kCrcBytes;
    for (const LightTree* tree : trees) {
        blobs.push_back(serializeLightTree(*tree));
        total += blobs.back().size();
    }
    Writer out(total);
    out.bytes().insert(out.bytes().end(), std::begin(kTreesMagic), std::end(kTreesMagic));
    out.u32(kLightTreeFormatVersion);
    out.u32(static_cast<uint32_t>(trees.size()));
    for (const auto& blob : blobs) {
        out.u32(static_cast<uint32_t>(blob.size()));
        out.u32(static_cast<uint32_t>(uint64_t(blob.size()) >> 32));
    }
    for (const auto& blob : blobs) out.bytes().insert(out.bytes().end(), blob.begin(), blob.end());
    out.u32(util::crc32Of(out.bytes().data(), out.bytes().size()));
    return std::move(out.bytes());
}

std::vector<LightTree> deserializeLightTrees(const uint8_t* data, size_t size) {
    if (size > 0 && data == nullptr) throw std::invalid_argument("deserializeLightTrees: null data");
    if (size < kTreesHeaderBytes + kCrcBytes || std::memcmp(data, kTreesMagic, sizeof kTreesMagic) != 0)
        throw std::runtime_error("not a blob of VRL light trees (too short, or it does not start with \"VRLTREES\")");
    Reader header(data + sizeof kTreesMagic, kTreesHeaderBytes - sizeof kTreesMagic);
    const uint32_t version = header.u32();
    if (version != kLightTreeFormatVersion)
        throw std::runtime_error("light trees blob has format version " + std::to_string(version) +
                                 " but this build reads version " + std::to_string(kLightTreeFormatVersion));
    const uint32_t count = header.u32();
    if (count < 1 || count > kMaxLightTreesInBlob)
        throw std::runtime_error("light trees blob declares " + std::to_string(count) + " trees, outside 1 ... " +
                                 std::to_string(kMaxLightTreesInBlob));
    const uint64_t sizesEnd = kTreesHeaderBytes + 8 * uint64_t(count);
    if (size < sizesEnd + kCrcBytes)
        throw std::runtime_error("light trees blob is truncated: its " + std::to_string(count) +
                                 " tree sizes need " + std::to_string(sizesEnd + kCrcBytes) + " bytes, found " +
                                 std::to_string(size));
    Reader sizes(data + kTreesHeaderBytes, 8 * size_t(count));
    std::vector<uint64_t> treeBytes(count);
    uint64_t expected = sizesEnd + kCrcBytes;
    for (uint64_t& bytes : treeBytes) {
        const uint64_t low = sizes.u32(), high = sizes.u32();
        bytes = low | (high << 32);
        if (bytes > size) throw std::runtime_error("light trees blob is corrupt: a tree size exceeds the blob");
        expected += bytes;
    }
    if (expected != size)
        throw std::runtime_error("light trees blob has the wrong size: its header declares " + std::to_string(expected) +
                                 " bytes, found " + std::to_string(size));
    const uint32_t storedCrc = Reader(data + size - kCrcBytes, kCrcBytes).u32();
    if (storedCrc != util::crc32Of(data, size - kCrcBytes))
        throw std::runtime_error("light trees blob is corrupt: checksum mismatch");
    std::vector<LightTree> trees;
    trees.reserve(count);
    size_t offset = sizesEnd;
    for (uint32_t k = 0; k < count; ++k) {
        try {
            trees.push_back(deserializeLightTree(data + offset, treeBytes[k]));
        } catch (const std::runtime_error& e) {
            throw std::runtime_error("light tree " + std::to_string(k) + " of " + std::to_string(count) + ": " +
                                     e.what());
        }
        offset += treeBytes[k];
    }
    return trees;
}

std::vector<uint8_t> serializeSurfaceVpls(const SurfaceVplLights& lights) {
    if (lights.vpls.size() > UINT32_MAX)
        throw std::invalid_argument("too many surface VPLs to serialise (over 2^32 - 1)");
    if (!lights.tree.empty() && lights.tree.vrls().size() != lights.vpls.size())
        throw std::invalid_argument("serializeSurfaceVpls: the tree holds " + std::to_string(lights.tree.vrls().size()) +
                                    " lights but the list " + std::to_string(lights.vpls.size()) + " VPLs");
    const std::vector<uint8_t> tree = lights.tree.empty() ? std::vector<uint8_t>() : serializeLightTree(lights.tree);
    Writer out(kSurfaceHeaderBytes + lights.vpls.size() * kSurfaceVplBytes + 4 + (tree.empty() ? 0 : 8 + tree.size()) +
               kCrcBytes);
    out.bytes().insert(out.bytes().end(), std::begin(kSurfaceMagic), std::end(kSurfaceMagic));
    out.u32(kLightTreeFormatVersion);
    out.u32(static_cast<uint32_t>(lights.vpls.size()));
    for (const SurfaceVpl& v : lights.vpls) writeSurfaceVpl(out, v);
    out.u32(tree.empty() ? 0 : 1);
    if (!tree.empty()) {
        out.u64(tree.size());
        out.bytes(tree);
    }
    out.u32(util::crc32Of(out.bytes().data(), out.bytes().size()));
    return std::move(out.bytes());
}

SurfaceVplLights deserializeSurfaceVpls(const uint8_t* data, size_t size) {
    if (size > 0 && data == nullptr) throw std::invalid_argument("deserializeSurfaceVpls: null data");
    if (size < kSurfaceHeaderBytes || std::memcmp(data, kSurfaceMagic, sizeof kSurfaceMagic) != 0)
        throw std::runtime_error("not a surface VPL blob (too short, or it does not start with \"VRLSVPLS\")");
    Reader header(data + sizeof kSurfaceMagic, kSurfaceHeaderBytes - sizeof kSurfaceMagic);
    const uint32_t version = header.u32();
    if (version != kLightTreeFormatVersion)
        throw std::runtime_error("surface VPL blob has format version " + std::to_string(version) +
                                 " but this build reads version " + std::to_string(kLightTreeFormatVersion) +
                                 "; coordinator and workers must be the same release");
    const uint32_t count = header.u32();
    const uint64_t vplsEnd = kSurfaceHeaderBytes + uint64_t(count) * kSurfaceVplBytes;  // < 2^39: no overflow
    const uint64_t withoutTree = vplsEnd + 4 + kCrcBytes;
    if (size < withoutTree)
        throw std::runtime_error("surface VPL blob is truncated (or its header corrupt): expected at least " +
                                 std::to_string(withoutTree) + " bytes for the " + std::to_string(count) +
                                 " VPLs its header declares, found " + std::to_string(size));
    Reader flags(data + vplsEnd, size - vplsEnd);
    const uint32_t hasTree = flags.u32();
    if (hasTree > 1)
        throw std::runtime_error("surface VPL blob is corrupt: its tree flag is " + std::to_string(hasTree) +
                                 ", not 0 or 1");
    uint64_t treeBytes = 0, expected = withoutTree;
    if (hasTree) {
        if (size < withoutTree + 8)
            throw std::runtime_error("surface VPL blob is truncated: it declares a tree but ends before its size (" +
                                     std::to_string(size) + " bytes)");
        treeBytes = flags.u64();
        if (treeBytes > size)
            throw std::runtime_error("surface VPL blob is corrupt: its tree size " + std::to_string(treeBytes) +
                                     " exceeds the blob (" + std::to_string(size) + " bytes)");
        expected += 8 + treeBytes;
    }
    if (size != expected)
        throw std::runtime_error("surface VPL blob has the wrong size: its header declares " + std::to_string(expected) +
                                 " bytes (" + std::to_string(count) + " VPLs" +
                                 (hasTree ? " and a tree of " + std::to_string(treeBytes) + " bytes" : "") +
                                 "), found " + std::to_string(size));
    const uint32_t storedCrc = Reader(data + size - kCrcBytes, kCrcBytes).u32();
    const uint32_t actualCrc = util::crc32Of(data, size - kCrcBytes);
    if (storedCrc != actualCrc)
        throw std::runtime_error("surface VPL blob is corrupt: checksum mismatch (stored CRC-32 " +
                                 std::to_string(storedCrc) + ", computed " + std::to_string(actualCrc) + ")");
    SurfaceVplLights lights;
    Reader in(data + kSurfaceHeaderBytes, vplsEnd - kSurfaceHeaderBytes);
    lights.vpls.resize(count);  // sizes verified against the blob above
    for (SurfaceVpl& v : lights.vpls) v = readSurfaceVpl(in);
    if (hasTree) {
        try {
            lights.tree = deserializeLightTree(data + vplsEnd + 4 + 8, treeBytes);
        } catch (const std::runtime_error& e) {
            throw std::runtime_error(std::string("surface VPL blob: its tree: ") + e.what());
        }
        if (lights.tree.empty() || lights.tree.vrls().size() != count)
            throw std::runtime_error("surface VPL blob is inconsistent: its tree holds " +
                                     std::to_string(lights.tree.vrls().size()) + " lights" +
                                     (lights.tree.empty() ? " (an empty tree is written as none)" : "") +
                                     ", but there must be one per VPL (" + std::to_string(count) + ")");
    }
    return lights;
}

std::vector<uint8_t> serializeJobLights(std::span<const uint8_t> primary, std::span<const uint8_t> surfaceVpls) {
    Writer out(kJobHeaderBytes + primary.size() + surfaceVpls.size() + kCrcBytes);
    out.bytes().insert(out.bytes().end(), std::begin(kJobMagic), std::end(kJobMagic));
    out.u32(kLightTreeFormatVersion);
    out.u64(primary.size());
    out.u64(surfaceVpls.size());
    out.bytes(primary);
    out.bytes(surfaceVpls);
    out.u32(util::crc32Of(out.bytes().data(), out.bytes().size()));
    return std::move(out.bytes());
}

JobLightsParts parseJobLights(const uint8_t* data, size_t size) {
    if (size > 0 && data == nullptr) throw std::invalid_argument("parseJobLights: null data");
    if (size < kJobHeaderBytes + kCrcBytes || std::memcmp(data, kJobMagic, sizeof kJobMagic) != 0)
        throw std::runtime_error("not a job lights blob (too short, or it does not start with \"VRLLIGHT\"); "
                                 "are the coordinator and this worker the same release?");
    Reader header(data + sizeof kJobMagic, kJobHeaderBytes - sizeof kJobMagic);
    const uint32_t version = header.u32();
    if (version != kLightTreeFormatVersion)
        throw std::runtime_error("job lights blob has format version " + std::to_string(version) +
                                 " but this build reads version " + std::to_string(kLightTreeFormatVersion));
    const uint64_t primaryBytes = header.u64(), surfaceBytes = header.u64();
    if (primaryBytes > size || surfaceBytes > size ||
        kJobHeaderBytes + primaryBytes + surfaceBytes + kCrcBytes != size)
        throw std::runtime_error("job lights blob has the wrong size: its header declares parts of " +
                                 std::to_string(primaryBytes) + " and " + std::to_string(surfaceBytes) +
                                 " bytes, which with header and checksum do not make the " + std::to_string(size) +
                                 " bytes found");
    const uint32_t storedCrc = Reader(data + size - kCrcBytes, kCrcBytes).u32();
    if (storedCrc != util::crc32Of(data, size - kCrcBytes))
        throw std::runtime_error("job lights blob is corrupt: checksum mismatch");
    const uint8_t* primary = data + kJobHeaderBytes;
    return {{primary, size_t(primaryBytes)}, {primary + primaryBytes, size_t(surfaceBytes)}};
}

}  // namespace vrl
