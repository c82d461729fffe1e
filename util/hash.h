// Checksums and digests: SHA-256 (OpenSSL) names scene bundles, light blobs and
// report caches by content; CRC-32 (zlib) guards streamed chunks and serialised
// light trees against corruption. Pure functions of the bytes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace vrl::util {

// Lowercase hex SHA-256 of the bytes (64 digits).
std::string sha256Hex(std::string_view bytes);
// True for 64 lowercase hex digits (what sha256Hex writes).
bool isSha256Hex(std::string_view text);
// CRC-32 (zlib's polynomial) of the bytes.
uint32_t crc32Of(std::string_view bytes);
inline uint32_t crc32Of(const uint8_t* data, size_t size) {
    return crc32Of(std::string_view(reinterpret_cast<const char*>(data), size));
}

}  // namespace vrl::util
