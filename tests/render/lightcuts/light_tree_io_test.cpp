#include "render/lightcuts/tree/light_tree_io.h"

#include "render/core/rng.h"

#include <gtest/gtest.h>

#include <zlib.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace vrl {
namespace {

constexpr size_t kHeaderBytes = 24, kVrlBytes = 44, kNodeBytes = 72;

uint32_t bits(float f) { return std::bit_cast<uint32_t>(f); }

void expectSameBits(const Imath::V3f& a, const Imath::V3f& b, const std::string& what) {
    for (int k = 0; k < 3; ++k) EXPECT_EQ(bits(a[k]), bits(b[k])) << what << "[" << k << "]";
}

// Field by field (no memcmp over padding), floats by bit pattern.
void expectSameTree(const LightTree& a, const LightTree& b) {
    ASSERT_EQ(a.root(), b.root());
    ASSERT_EQ(a.vrls().size(), b.vrls().size());
    ASSERT_EQ(a.nodes().size(), b.nodes().size());
    for (size_t i = 0; i < a.vrls().size(); ++i) {
        const Vrl &x = a.vrls()[i], &y = b.vrls()[i];
        const std::string at = "vrl " + std::to_string(i) + " ";
        expectSameBits(x.origin, y.origin, at + "origin");
        expectSameBits(x.direction, y.direction, at + "direction");
        EXPECT_EQ(bits(x.length), bits(y.length)) << at;
        expectSameBits(x.flux, y.flux, at + "flux");
        EXPECT_EQ(x.medium, y.medium) << at;
    }
    for (size_t i = 0; i < a.nodes().size(); ++i) {
        const LightTreeNode &x = a.nodes()[i], &y = b.nodes()[i];
        const std::string at = "node " + std::to_string(i) + " ";
        expectSameBits(x.box.min, y.box.min, at + "box.min");
        expectSameBits(x.box.max, y.box.max, at + "box.max");
        expectSameBits(x.fluxLength, y.fluxLength, at + "fluxLength");
        expectSameBits(x.clusterFlux, y.clusterFlux, at + "clusterFlux");
        EXPECT_EQ(bits(x.maxLength), bits(y.maxLength)) << at;
        EXPECT_EQ(x.representative, y.representative) << at;
        EXPECT_EQ(x.vrlCount, y.vrlCount) << at;
        EXPECT_EQ(x.left, y.left) << at;
        EXPECT_EQ(x.right, y.right) << at;
        EXPECT_EQ(x.medium, y.medium) << at;
    }
}

void expectRoundTrip(const LightTree& tree) {
    const std::vector<uint8_t> blob = serializeLightTree(tree);
    EXPECT_EQ(blob.size(), kHeaderBytes + kVrlBytes * tree.vrls().size() + kNodeBytes * tree.nodes().size() + 4);
    const LightTree back = deserializeLightTree(blob);
    expectSameTree(tree, back);
    EXPECT_EQ(serializeLightTree(back), blob);
}

// A consistent tree by hand: leaves are VRLs 0..n-1, then one inner node per
// (left, right) merge, in order; the root is the last node.
LightTree makeTree(std::vector<Vrl> vrls, const std::vector<std::pair<int32_t, int32_t>>& merges) {
    std::vector<LightTreeNode> nodes;
    for (size_t i = 0; i < vrls.size(); ++i) {
        const Vrl& v = vrls[i];
        LightTreeNode n;
        n.box.extendBy(v.origin);
        n.box.extendBy(v.end());
        n.fluxLength = v.flux * v.length;
        n.clusterFlux = v.flux;
        n.maxLength = v.length;
        n.representative = uint32_t(i);
        n.vrlCount = 1;
        n.medium = v.medium;
        nodes.push_back(n);
    }
    for (auto [l, r] : merges) {
        const LightTreeNode a = nodes[l], b = nodes[r];
        LightTreeNode n;
        n.box = a.box;
        n.box.extendBy(b.box);
        n.fluxLength = a.fluxLength + b.fluxLength;
        n.representative = a.representative;
        n.clusterFlux = n.fluxLength / vrls[n.representative].length;
        n.maxLength = std::max(a.maxLength, b.maxLength);
        n.vrlCount = a.vrlCount + b.vrlCount;
        n.left = l, n.right = r;
        n.medium = a.medium == b.medium ? a.medium : -1;
        nodes.push_back(n);
    }
    const auto root = vrls.empty() ? -1 : int32_t(nodes.size()) - 1;
    return LightTree::fromParts(std::move(vrls), std::move(nodes), root);
}

Vrl randomVrl(Rng& rng) {
    Vrl v;
    v.origin = {rng.next() * 4 - 2, rng.next() * 4 - 2, rng.next() * 4 - 2};
    v.direction = Vec3(rng.next() - 0.5f, rng.next() - 0.5f, rng.next() - 0.5f).normalized();
    v.length = 0.01f + rng.next();
    v.flux = {rng.next(), rng.next(), rng.next()};
    v.medium = int32_t(rng.nextUint() % 3);
    return v;
}

// Three leaves and two inner nodes: ((0, 1), 2).
LightTree smallTree() {
    Rng rng(7, 0);
    return makeTree({randomVrl(rng), randomVrl(rng), randomVrl(rng)}, {{0, 1}, {3, 2}});
}

void putU32(std::vector<uint8_t>& blob, size_t offset, uint32_t v) {
    for (int i = 0; i < 4; ++i) blob[offset + i] = uint8_t(v >> (8 * i));
}
void resealCrc(std::vector<uint8_t>& blob) {
    putU32(blob, blob.size() - 4, uint32_t(crc32(0L, blob.data(), uInt(blob.size() - 4))));
}

// Expects a std::runtime_error whose message contains every one of `parts`.
void expectRejected(const std::vector<uint8_t>& blob, const std::vector<std::string>& parts,
                    const std::string& context = "") {
    try {
        deserializeLightTree(blob);
        ADD_FAILURE() << "accepted a bad blob " << context;
    } catch (const std::runtime_error& e) {
        for (const std::string& part : parts)
            EXPECT_NE(std::string(e.what()).find(part), std::string::npos)
                << "message \"" << e.what() << "\" lacks \"" << part << "\" " << context;
    }
}

TEST(LightTreeIo, SingleLeafRoundTripsBitExactly) {
    Vrl v;
    v.origin = {-0.0f, 1.5f, 0.0f};
    v.direction = {0.0f, -0.0f, 1.0f};
    v.length = 0.25f;
    v.flux = {3.0f, std::bit_cast<float>(0x7fc12345u), std::bit_cast<float>(0xffa00001u)};  // NaN payloads
    v.medium = 2;
    expectRoundTrip(makeTree({v}, {}));
}

TEST(LightTreeIo, ThreeLeavesTwoInnerNodesRoundTrip) { expectRoundTrip(smallTree()); }

TEST(LightTreeIo, RandomTreeOfHundredsOfVrlsRoundTrips) {
    Rng rng(20240611, 1);  // seed, stream
    std::vector<Vrl> vrls;
    for (int i = 0; i < 317; ++i) vrls.push_back(randomVrl(rng));
    // Random binary tree: merge two random subtrees until one remains.
    std::vector<int32_t> open;
    for (int32_t i = 0; i < int32_t(vrls.size()); ++i) open.push_back(i);
    std::vector<std::pair<int32_t, int32_t>> merges;
    for (int32_t next = int32_t(vrls.size()); open.size() > 1; ++next) {
        std::swap(open[rng.nextUint() % open.size()], open.back());
        const int32_t a = open.back();
        open.pop_back();
        std::swap(open[rng.nextUint() % open.size()], open.back());
        merges.push_back({a, open.back()});
        open.back() = next;
    }
    const LightTree tree = makeTree(std::move(vrls), merges);
    ASSERT_EQ(tree.nodes()[size_t(tree.root())].vrlCount, 317u);
    expectRoundTrip(tree);
}

// An inner node's fluxes scale inherited cut estimates: NaN, infinite or negative
// ones are refused by name.
TEST(LightTreeIo, InnerNodesWithBadFluxAreRefused) {
    const LightTree good = smallTree();
    for (const float bad : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(), -1.0f}) {
        for (const bool cluster : {true, false}) {
            std::vector<LightTreeNode> nodes = good.nodes();
            Rgb& flux = cluster ? nodes[3].clusterFlux : nodes[3].fluxLength;
            flux.y = bad;
            try {
                LightTree::fromParts(good.vrls(), nodes, good.root());
                ADD_FAILURE() << "accepted flux " << bad;
            } catch (const std::invalid_argument& e) {
                EXPECT_NE(std::string(e.what()).find("node 3 has a negative or non-finite flux"), std::string::npos)
                    << e.what();
            }
        }
    }
}

TEST(LightTreeIo, EmptyTreeRoundTrips) {
    expectRoundTrip(LightTree());
    EXPECT_TRUE(deserializeLightTree(serializeLightTree(LightTree())).empty());
}

TEST(LightTreeIo, LayoutIsLittleEndianFieldByField) {
    const std::vector<uint8_t> blob = serializeLightTree(smallTree());
    EXPECT_EQ(std::string(blob.begin(), blob.begin() + 8), std::string("VRLTREE\0", 8));
    const std::vector<uint8_t> counts(blob.begin() + 8, blob.begin() + 24);
    EXPECT_EQ(counts, (std::vector<uint8_t>{kLightTreeFormatVersion, 0, 0, 0, 3, 0, 0, 0, 5, 0, 0, 0, 4, 0, 0, 0}));
}

TEST(LightTreeIo, RejectsWrongMagic) {
    std::vector<uint8_t> blob = serializeLightTree(smallTree());
    blob[3] = 'X';
    expectRejected(blob, {"not a VRL light tree"});
    expectRejected({'P', 'K', 3}, {"not a VRL light tree"});
}

TEST(LightTreeIo, RejectsOtherFormatVersionNamingBoth) {
    std::vector<uint8_t> blob = serializeLightTree(smallTree());
    putU32(blob, 8, kLightTreeFormatVersion + 1);
    resealCrc(blob);
    expectRejected(blob, {"version " + std::to_string(kLightTreeFormatVersion + 1),
                          "version " + std::to_string(kLightTreeFormatVersion)});
}

TEST(LightTreeIo, RejectsEveryTruncation) {
    const std::vector<uint8_t> blob = serializeLightTree(smallTree());
    for (size_t n = 0; n < blob.size(); ++n) {
        // A copy of exactly n bytes, so a sanitizer sees any read past its end.
        const std::vector<uint8_t> cut(blob.begin(), blob.begin() + n);
        expectRejected(cut, {"truncated", "expected", "found " + std::to_string(n)}, "at " + std::to_string(n));
    }
}

TEST(LightTreeIo, RejectsTrailingBytes) {
    std::vector<uint8_t> blob = serializeLightTree(smallTree());
    blob.push_back(0);
    expectRejected(blob, {"longer than expected", "found " + std::to_string(blob.size())});
}

TEST(LightTreeIo, RejectsEveryFlippedBit) {
    const std::vector<uint8_t> blob = serializeLightTree(smallTree());
    for (size_t byte = 0; byte < blob.size(); ++byte) {
        for (int bit = 0; bit < 8; ++bit) {
            std::vector<uint8_t> bad = blob;
            bad[byte] ^= uint8_t(1u << bit);
            // The magic, version and counts fields have their own messages; past them, the checksum.
            const bool pastCounts = byte >= 20;
            expectRejected(bad, pastCounts ? std::vector<std::string>{"checksum"} : std::vector<std::string>{},
                           "flipping byte " + std::to_string(byte) + " bit " + std::to_string(bit));
        }
    }
}

TEST(LightTreeIo, RejectsHugeCountsWithoutAllocating) {
    for (uint32_t nodes : {5u, 0xffffffffu}) {
        std::vector<uint8_t> blob = serializeLightTree(smallTree());
        putU32(blob, 12, 1u << 31);
        putU32(blob, 16, nodes);
        resealCrc(blob);
        // Allocating 2^31 VRLs (94 GB) first would throw std::bad_alloc or die, not this.
        expectRejected(blob, {"2147483648 VRLs", "found " + std::to_string(blob.size()) + " bytes"});
    }
}

TEST(LightTreeIo, RejectsStructurallyInvalidTreeWithValidChecksum) {
    std::vector<uint8_t> blob = serializeLightTree(smallTree());
    const size_t rootNode = kHeaderBytes + 3 * kVrlBytes + 4 * kNodeBytes;
    putU32(blob, rootNode + 60, 99);  // `left` of the root (after 13 floats and 2 uint32s): out of range
    resealCrc(blob);
    expectRejected(blob, {"structurally invalid", "out of range"});
}

// ---- several trees in one blob (vrl-stochastic with --vrl-sets)

// Expects deserializeLightTrees to throw std::runtime_error naming every one of `parts`.
void expectTreesRejected(const std::vector<uint8_t>& blob, const std::vector<std::string>& parts,
                         const std::string& context = "") {
    try {
        deserializeLightTrees(blob.data(), blob.size());
        ADD_FAILURE() << "accepted a bad blob " << context;
    } catch (const std::runtime_error& e) {
        for (const std::string& part : parts)
            EXPECT_NE(std::string(e.what()).find(part), std::string::npos)
                << "message \"" << e.what() << "\" lacks \"" << part << "\" " << context;
    }
}

std::vector<LightTree> threeTrees() {
    Rng rng(99, 3);
    std::vector<LightTree> trees;
    trees.push_back(smallTree());
    trees.push_back(LightTree());  // a set whose light tracing found no VRL keeps its place
    trees.push_back(makeTree({randomVrl(rng), randomVrl(rng)}, {{0, 1}}));
    return trees;
}

std::vector<uint8_t> threeTreesBlob() {
    const std::vector<LightTree> trees = threeTrees();
    return serializeLightTrees({&trees[0], &trees[1], &trees[2]});
}

TEST(LightTreesIo, SeveralTreesRoundTripBitExactlyInOrder) {
    const std::vector<LightTree> trees = threeTrees();
    const std::vector<uint8_t> blob = threeTreesBlob();
    // Header (magic, version, count), three u64 sizes, the three tree blobs, the CRC.
    size_t expected = 8 + 4 + 4 + 3 * 8 + 4;
    for (const LightTree& tree : trees) expected += serializeLightTree(tree).size();
    EXPECT_EQ(blob.size(), expected);
    const std::vector<LightTree> back = deserializeLightTrees(blob.data(), blob.size());
    ASSERT_EQ(back.size(), 3u);
    for (size_t k = 0; k < 3; ++k) expectSameTree(trees[k], back[k]);
    EXPECT_TRUE(back[1].empty());
    EXPECT_EQ(serializeLightTrees({&back[0], &back[1], &back[2]}), blob);
}

TEST(LightTreesIo, RejectsNoTreesOrTooManyWhenWriting) {
    EXPECT_THROW(serializeLightTrees({}), std::invalid_argument);
    const LightTree tree = smallTree();
    const std::vector<const LightTree*> many(kMaxLightTreesInBlob + 1, &tree);
    EXPECT_THROW(serializeLightTrees(many), std::invalid_argument);
}

TEST(LightTreesIo, RejectsASingleTreeBlobAndWrongVersion) {
    const std::vector<uint8_t> single = serializeLightTree(smallTree());
    expectTreesRejected(single, {"VRLTREES"});
    std::vector<uint8_t> blob = threeTreesBlob();
    putU32(blob, 8, kLightTreeFormatVersion + 1);
    resealCrc(blob);
    expectTreesRejected(blob, {"format version " + std::to_string(kLightTreeFormatVersion + 1)});
}

TEST(LightTreesIo, RejectsCountsOutOfRangeWithoutAllocating) {
    for (uint32_t count : {0u, kMaxLightTreesInBlob + 1, 0xffffffffu}) {
        std::vector<uint8_t> blob = threeTreesBlob();
        putU32(blob, 12, count);
        resealCrc(blob);
        expectTreesRejected(blob, {"declares " + std::to_string(count) + " trees"});
    }
    std::vector<uint8_t> blob = threeTreesBlob();
    putU32(blob, 12, 1000);  // in range, but its sizes would run past the blob
    resealCrc(blob);
    expectTreesRejected(blob, {"truncated"});
}

TEST(LightTreesIo, RejectsEveryTruncationAndTrailingBytes) {
    const std::vector<uint8_t> blob = threeTreesBlob();
    for (size_t n = 0; n < blob.size(); ++n) {
        const std::vector<uint8_t> cut(blob.begin(), blob.begin() + n);
        expectTreesRejected(cut, {}, "at " + std::to_string(n));
    }
    std::vector<uint8_t> longer = blob;
    longer.push_back(0);
    expectTreesRejected(longer, {"wrong size"});
}

TEST(LightTreesIo, RejectsTreeSizesThatDoNotAddUp) {
    std::vector<uint8_t> blob = threeTreesBlob();
    // First tree's size one byte more, second's one less: the total still fits, the trees do not.
    const uint32_t first = uint32_t(blob[16]) | uint32_t(blob[17]) << 8 | uint32_t(blob[18]) << 16 | uint32_t(blob[19]) << 24;
    const uint32_t second = uint32_t(blob[24]) | uint32_t(blob[25]) << 8 | uint32_t(blob[26]) << 16 | uint32_t(blob[27]) << 24;
    putU32(blob, 16, first + 1);
    putU32(blob, 24, second - 1);
    resealCrc(blob);
    expectTreesRejected(blob, {"light tree 0 of 3", "longer than expected"});
    blob = threeTreesBlob();
    putU32(blob, 20, 1);  // a size's high word: past the blob
    resealCrc(blob);
    expectTreesRejected(blob, {"exceeds the blob"});
}

TEST(LightTreesIo, RejectsEveryFlippedBit) {
    const std::vector<uint8_t> blob = threeTreesBlob();
    for (size_t byte = 0; byte < blob.size(); ++byte)
        for (int bit = 0; bit < 8; ++bit) {
            std::vector<uint8_t> bad = blob;
            bad[byte] ^= uint8_t(1u << bit);
            expectTreesRejected(bad, {}, "flipping byte " + std::to_string(byte) + " bit " + std::to_string(bit));
        }
}

// ---- part (b)'s surface VPLs, and the job's lights blob that ships them with the VRLs

constexpr size_t kSurfaceHeaderBytes = 16, kSurfaceVplBytes = 84;

SurfaceVpl randomSurfaceVpl(Rng& rng) {
    SurfaceVpl v;
    v.position = {rng.next() * 4 - 2, rng.next() * 4 - 2, rng.next() * 4 - 2};
    v.geometricNormal = Vec3(rng.next() - 0.5f, rng.next() - 0.5f, rng.next() - 0.5f).normalized();
    v.shadingNormal = Vec3(rng.next() - 0.5f, rng.next() - 0.5f, rng.next() - 0.5f).normalized();
    v.uv = {rng.next(), rng.next()};
    v.shape = rng.nextUint() % 7;
    v.triangle = rng.nextUint();
    v.scale = 0.5f + rng.next();
    v.direction = Vec3(rng.next() - 0.5f, rng.next() - 0.5f, rng.next() - 0.5f).normalized();
    v.flux = {rng.next(), rng.next(), rng.next()};
    v.medium = int32_t(rng.nextUint() % 3) - 1;
    return v;
}

// Three VPLs with the odd bit patterns a copy through floats would lose, and, with
// `withTree`, a tree over one proxy per VPL (as prepareSurfaceVpls builds it).
SurfaceVplLights surfaceVpls(bool withTree) {
    Rng rng(31, 5);  // seed, stream
    SurfaceVplLights lights;
    for (int k = 0; k < 3; ++k) lights.vpls.push_back(randomSurfaceVpl(rng));
    lights.vpls[0].position.x = -0.0f;
    lights.vpls[1].flux.y = std::bit_cast<float>(0x7fc12345u);  // a NaN payload
    lights.vpls[2].uv.y = std::bit_cast<float>(0x00000001u);     // a denormal
    lights.vpls[2].triangle = 0xffffffffu;
    if (withTree) {
        std::vector<Vrl> proxies;  // a point light per VPL, its "flux" an intensity bound
        for (const SurfaceVpl& vpl : lights.vpls) {
            Vrl proxy;
            proxy.origin = vpl.position;
            proxy.direction = vpl.shadingNormal;
            proxy.length = 0.0f;
            proxy.flux = {0.5f + rng.next(), 0.5f + rng.next(), 0.5f + rng.next()};
            proxy.medium = vpl.medium;
            proxies.push_back(proxy);
        }
        lights.tree = LightTree::build(std::move(proxies), LightTreeSettings{2048, 17, true});
    }
    return lights;
}

void expectSameSurfaceVpls(const SurfaceVplLights& a, const SurfaceVplLights& b) {
    ASSERT_EQ(a.vpls.size(), b.vpls.size());
    for (size_t i = 0; i < a.vpls.size(); ++i) {
        const SurfaceVpl &x = a.vpls[i], &y = b.vpls[i];
        const std::string at = "vpl " + std::to_string(i) + " ";
        expectSameBits(x.position, y.position, at + "position");
        expectSameBits(x.geometricNormal, y.geometricNormal, at + "geometricNormal");
        expectSameBits(x.shadingNormal, y.shadingNormal, at + "shadingNormal");
        EXPECT_EQ(bits(x.uv.x), bits(y.uv.x)) << at;
        EXPECT_EQ(bits(x.uv.y), bits(y.uv.y)) << at;
        EXPECT_EQ(x.shape, y.shape) << at;
        EXPECT_EQ(x.triangle, y.triangle) << at;
        EXPECT_EQ(bits(x.scale), bits(y.scale)) << at;
        expectSameBits(x.direction, y.direction, at + "direction");
        expectSameBits(x.flux, y.flux, at + "flux");
        EXPECT_EQ(x.medium, y.medium) << at;
    }
    expectSameTree(a.tree, b.tree);
}

void expectSurfaceRejected(const std::vector<uint8_t>& blob, const std::vector<std::string>& parts,
                           const std::string& context = "") {
    try {
        deserializeSurfaceVpls(blob.data(), blob.size());
        ADD_FAILURE() << "accepted a bad blob " << context;
    } catch (const std::runtime_error& e) {
        for (const std::string& part : parts)
            EXPECT_NE(std::string(e.what()).find(part), std::string::npos)
                << "message \"" << e.what() << "\" lacks \"" << part << "\" " << context;
    }
}

TEST(SurfaceVplIo, VplsWithoutATreeRoundTripBitExactly) {
    const SurfaceVplLights lights = surfaceVpls(false);
    const std::vector<uint8_t> blob = serializeSurfaceVpls(lights);
    EXPECT_EQ(blob.size(), kSurfaceHeaderBytes + 3 * kSurfaceVplBytes + 4 + 4);  // + tree flag, crc
    EXPECT_EQ(std::string(blob.begin(), blob.begin() + 8), "VRLSVPLS");
    const SurfaceVplLights back = deserializeSurfaceVpls(blob.data(), blob.size());
    EXPECT_TRUE(back.tree.empty());
    expectSameSurfaceVpls(lights, back);
    EXPECT_EQ(serializeSurfaceVpls(back), blob);
}

TEST(SurfaceVplIo, VplsWithTheirTreeRoundTripBitExactly) {
    const SurfaceVplLights lights = surfaceVpls(true);
    const std::vector<uint8_t> blob = serializeSurfaceVpls(lights);
    const std::vector<uint8_t> tree = serializeLightTree(lights.tree);
    EXPECT_EQ(blob.size(), kSurfaceHeaderBytes + 3 * kSurfaceVplBytes + 4 + 8 + tree.size() + 4);
    // The tree is serializeLightTree's blob, verbatim, after its flag and size.
    const size_t treeAt = kSurfaceHeaderBytes + 3 * kSurfaceVplBytes + 4 + 8;
    EXPECT_EQ(std::vector<uint8_t>(blob.begin() + treeAt, blob.begin() + treeAt + tree.size()), tree);
    const SurfaceVplLights back = deserializeSurfaceVpls(blob.data(), blob.size());
    EXPECT_FALSE(back.tree.empty());
    expectSameSurfaceVpls(lights, back);
    EXPECT_EQ(serializeSurfaceVpls(back), blob);
}

TEST(SurfaceVplIo, NoVplsRoundTrip) {
    const std::vector<uint8_t> blob = serializeSurfaceVpls(SurfaceVplLights());
    const SurfaceVplLights back = deserializeSurfaceVpls(blob.data(), blob.size());
    EXPECT_TRUE(back.vpls.empty());
    EXPECT_TRUE(back.tree.empty());
}

TEST(SurfaceVplIo, RefusesToWriteATreeOfAnotherSize) {
    SurfaceVplLights lights = surfaceVpls(true);
    lights.vpls.pop_back();
    EXPECT_THROW(serializeSurfaceVpls(lights), std::invalid_argument);
}

TEST(SurfaceVplIo, RejectsWrongMagicAndVersion) {
    std::vector<uint8_t> blob = serializeSurfaceVpls(surfaceVpls(true));
    expectSurfaceRejected(serializeLightTree(smallTree()), {"not a surface VPL blob", "VRLSVPLS"});
    std::vector<uint8_t> bad = blob;
    bad[4] = 'X';
    expectSurfaceRejected(bad, {"not a surface VPL blob"});
    putU32(blob, 8, kLightTreeFormatVersion + 1);
    resealCrc(blob);
    expectSurfaceRejected(blob, {"version " + std::to_string(kLightTreeFormatVersion + 1),
                                 "version " + std::to_string(kLightTreeFormatVersion)});
}

TEST(SurfaceVplIo, RejectsEveryTruncationAndTrailingBytes) {
    for (const bool withTree : {false, true}) {
        const std::vector<uint8_t> blob = serializeSurfaceVpls(surfaceVpls(withTree));
        for (size_t n = 0; n < blob.size(); ++n) {
            const std::vector<uint8_t> cut(blob.begin(), blob.begin() + n);  // exactly n bytes, for sanitizers
            expectSurfaceRejected(cut, {}, "at " + std::to_string(n));
        }
        std::vector<uint8_t> longer = blob;
        longer.push_back(0);
        expectSurfaceRejected(longer, {"wrong size", "found " + std::to_string(longer.size())});
    }
}

TEST(SurfaceVplIo, RejectsEveryFlippedBit) {
    const std::vector<uint8_t> blob = serializeSurfaceVpls(surfaceVpls(true));
    for (size_t byte = 0; byte < blob.size(); ++byte)
        for (int bit = 0; bit < 8; ++bit) {
            std::vector<uint8_t> bad = blob;
            bad[byte] ^= uint8_t(1u << bit);
            // Past the header, the VPLs' bytes are guarded by the checksum alone.
            const bool inVpls = byte >= kSurfaceHeaderBytes && byte < kSurfaceHeaderBytes + 3 * kSurfaceVplBytes;
            expectSurfaceRejected(bad, inVpls ? std::vector<std::string>{"checksum"} : std::vector<std::string>{},
                                  "flipping byte " + std::to_string(byte) + " bit " + std::to_string(bit));
        }
}

TEST(SurfaceVplIo, RejectsHugeCountsWithoutAllocating) {
    std::vector<uint8_t> blob = serializeSurfaceVpls(surfaceVpls(false));
    putU32(blob, 12, 0xffffffffu);
    resealCrc(blob);
    // Allocating 2^32 VPLs (360 GB) first would throw std::bad_alloc or die, not this.
    expectSurfaceRejected(blob, {"truncated", "4294967295 VPLs"});
}

TEST(SurfaceVplIo, RejectsABadTreeFlagOrTreeSize) {
    const size_t flagAt = kSurfaceHeaderBytes + 3 * kSurfaceVplBytes;
    std::vector<uint8_t> blob = serializeSurfaceVpls(surfaceVpls(true));
    putU32(blob, flagAt, 2);
    resealCrc(blob);
    expectSurfaceRejected(blob, {"tree flag is 2"});
    blob = serializeSurfaceVpls(surfaceVpls(true));
    putU32(blob, flagAt + 8, 1);  // the size's high word: past the blob
    resealCrc(blob);
    expectSurfaceRejected(blob, {"exceeds the blob"});
}

// A valid tree (its own checksum right) over another number of lights than there are VPLs.
TEST(SurfaceVplIo, RejectsATreeWhoseSizeDiffersFromTheVpls) {
    SurfaceVplLights lights = surfaceVpls(true);
    Rng rng(5, 5);
    lights.vpls.push_back(randomSurfaceVpl(rng));  // 4 VPLs, the tree's 3 proxies
    std::vector<uint8_t> blob;
    {
        // serializeSurfaceVpls refuses this, so write the 4 VPLs, then splice in the 3-light tree.
        SurfaceVplLights four;
        four.vpls = lights.vpls;
        blob = serializeSurfaceVpls(four);
        blob.resize(blob.size() - 8);  // drop the flag (0) and crc
        const std::vector<uint8_t> tree = serializeLightTree(lights.tree);
        const auto put = [&](uint32_t v) {
            for (int i = 0; i < 4; ++i) blob.push_back(uint8_t(v >> (8 * i)));
        };
        put(1);
        put(uint32_t(tree.size()));
        put(0);
        blob.insert(blob.end(), tree.begin(), tree.end());
        put(0);
        resealCrc(blob);
    }
    expectSurfaceRejected(blob, {"inconsistent", "tree holds 3 lights", "one per VPL (4)"});
    // And a tree that deserializeLightTree refuses is named as the surface VPLs' tree.
    std::vector<uint8_t> bad = serializeSurfaceVpls(surfaceVpls(true));
    const size_t treeAt = kSurfaceHeaderBytes + 3 * kSurfaceVplBytes + 4 + 8;
    bad[treeAt + 30] ^= 1;  // inside the tree: its own checksum fails
    resealCrc(bad);
    expectSurfaceRejected(bad, {"its tree", "checksum"});
}

// ---- the job's lights blob

void expectJobLightsRejected(const std::vector<uint8_t>& blob, const std::vector<std::string>& parts,
                             const std::string& context = "") {
    try {
        parseJobLights(blob.data(), blob.size());
        ADD_FAILURE() << "accepted a bad blob " << context;
    } catch (const std::runtime_error& e) {
        for (const std::string& part : parts)
            EXPECT_NE(std::string(e.what()).find(part), std::string::npos)
                << "message \"" << e.what() << "\" lacks \"" << part << "\" " << context;
    }
}

TEST(JobLightsIo, HoldsBothBlobsVerbatim) {
    const std::vector<uint8_t> primary = serializeLightTree(smallTree());
    const SurfaceVplLights lights = surfaceVpls(true);
    const std::vector<uint8_t> surface = serializeSurfaceVpls(lights);
    const std::vector<uint8_t> blob = serializeJobLights(primary, surface);
    EXPECT_EQ(blob.size(), 8 + 4 + 8 + 8 + primary.size() + surface.size() + 4);
    EXPECT_EQ(std::string(blob.begin(), blob.begin() + 8), "VRLLIGHT");
    const JobLightsParts parts = parseJobLights(blob.data(), blob.size());
    EXPECT_EQ(std::vector<uint8_t>(parts.primary.begin(), parts.primary.end()), primary);
    EXPECT_EQ(std::vector<uint8_t>(parts.surfaceVpls.begin(), parts.surfaceVpls.end()), surface);
    expectSameTree(smallTree(), deserializeLightTree(parts.primary.data(), parts.primary.size()));
    expectSameSurfaceVpls(lights, deserializeSurfaceVpls(parts.surfaceVpls.data(), parts.surfaceVpls.size()));
    EXPECT_EQ(serializeJobLights(parts.primary, parts.surfaceVpls), blob);
}

// Part (b) alone (--transport single): no VRLs are kept, the surface VPLs still ship.
TEST(JobLightsIo, AnEmptyPrimaryBlobIsNone) {
    const std::vector<uint8_t> surface = serializeSurfaceVpls(surfaceVpls(false));
    const std::vector<uint8_t> blob = serializeJobLights({}, surface);
    const JobLightsParts parts = parseJobLights(blob.data(), blob.size());
    EXPECT_TRUE(parts.primary.empty());
    EXPECT_EQ(std::vector<uint8_t>(parts.surfaceVpls.begin(), parts.surfaceVpls.end()), surface);
}

TEST(JobLightsIo, RejectsOtherBlobsTruncationSizesAndFlippedBits) {
    const std::vector<uint8_t> blob =
        serializeJobLights(serializeVrlSet(VrlSet{}), serializeSurfaceVpls(surfaceVpls(true)));
    expectJobLightsRejected(serializeLightTree(smallTree()), {"not a job lights blob", "VRLLIGHT"});
    std::vector<uint8_t> other = blob;
    putU32(other, 8, kLightTreeFormatVersion + 1);
    resealCrc(other);
    expectJobLightsRejected(other, {"format version " + std::to_string(kLightTreeFormatVersion + 1)});
    for (size_t n = 0; n < blob.size(); ++n)
        expectJobLightsRejected(std::vector<uint8_t>(blob.begin(), blob.begin() + n), {}, "at " + std::to_string(n));
    std::vector<uint8_t> longer = blob;
    longer.push_back(0);
    expectJobLightsRejected(longer, {"wrong size"});
    for (const uint32_t huge : {0xffffffffu, 1u}) {  // high words: sizes past the blob
        std::vector<uint8_t> bad = blob;
        putU32(bad, 16, huge);
        putU32(bad, 24, huge == 1u ? 0u : 0xffffffffu);
        resealCrc(bad);
        expectJobLightsRejected(bad, {"wrong size"});
    }
    for (size_t byte = 0; byte < blob.size(); ++byte)
        for (int bit = 0; bit < 8; ++bit) {
            std::vector<uint8_t> bad = blob;
            bad[byte] ^= uint8_t(1u << bit);
            expectJobLightsRejected(bad, {}, "flipping byte " + std::to_string(byte) + " bit " + std::to_string(bit));
        }
}

}  // namespace
}  // namespace vrl
