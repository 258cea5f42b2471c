#pragma once
// A valid 8x6 16-bit grey depth PNG (depth 1000 everywhere), built byte by byte without libpng:
// signature, IHDR, one IDAT holding a zlib stream of one stored block, IEND. The depth PNG
// harnesses' fixed image and a seed of their corpus.

#include <cstdint>
#include <string>

namespace groovetrace::fuzz {

inline const std::string& small_depth_png() {
  // 8x6, 16-bit grey, depth 1000 everywhere: signature, IHDR, one zlib-stored IDAT, IEND.
  static const std::string bytes = [] {
    auto be32 = [](std::uint32_t v) {
      return std::string{static_cast<char>(v >> 24), static_cast<char>(v >> 16),
                         static_cast<char>(v >> 8), static_cast<char>(v)};
    };
    auto crc = [](const std::string& s) {
      std::uint32_t c = 0xffffffffu;
      for (unsigned char b : s) {
        c ^= b;
        for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
      }
      return ~c;
    };
    auto chunk = [&](const std::string& type, const std::string& body) {
      return be32(static_cast<std::uint32_t>(body.size())) + type + body + be32(crc(type + body));
    };
    std::string raw;
    for (int r = 0; r < 6; ++r) {
      raw += '\0';  // filter: none
      for (int c = 0; c < 8; ++c) raw += std::string{'\x03', '\xe8'};
    }
    // zlib stream with one stored block: header, BFINAL stored block, LEN, NLEN, data, Adler-32.
    std::uint32_t a = 1, b = 0;
    for (unsigned char ch : raw) {
      a = (a + ch) % 65521;
      b = (b + a) % 65521;
    }
    const auto len = static_cast<std::uint16_t>(raw.size());
    std::string z = "\x78\x01\x01";
    z += std::string{static_cast<char>(len & 0xff), static_cast<char>(len >> 8),
                     static_cast<char>(~len & 0xff), static_cast<char>((~len >> 8) & 0xff)};
    z += raw + be32((b << 16) | a);
    const std::string ihdr = be32(8) + be32(6) + std::string{'\x10', '\0', '\0', '\0', '\0'};
    return std::string("\x89PNG\r\n\x1a\n", 8) + chunk("IHDR", ihdr) + chunk("IDAT", z) +
           chunk("IEND", "");
  }();
  return bytes;
}

}  // namespace groovetrace::fuzz
