// tests/support/image_check.hpp -- checks of the figures the tests produce: a PNG is decoded
// (signature, IHDR, IDAT inflated with zlib, scanline filters undone) to count its colours and find
// the dark straight lines of the axes; an SVG must parse as XML (TinyXML) with an <svg> root.
#pragma once

#include <tinyxml.h>
#include <zlib.h>

#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace ffsr::test {

struct PngImage {
  uint32_t width = 0, height = 0;
  int channels = 0;             ///< 3 (RGB) or 4 (RGBA)
  std::vector<uint8_t> pixels;  ///< row-major, `channels` bytes per pixel
  uint32_t rgb(uint32_t x, uint32_t y) const {
    const size_t i = (size_t(y) * width + x) * size_t(channels);
    return uint32_t(pixels[i]) << 16 | uint32_t(pixels[i + 1]) << 8 | pixels[i + 2];
  }
};

inline std::string read_binary(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot open " + path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Decodes an 8-bit RGB or RGBA, non-interlaced PNG (what PLplot's cairo driver writes); throws
/// std::runtime_error for anything else or a damaged file.
inline PngImage decode_png(const std::string& path) {
  const std::string f = read_binary(path);
  static const char sig[] = "\x89PNG\r\n\x1a\n";
  if (f.size() < 33 || f.compare(0, 8, std::string(sig, 8)) != 0)
    throw std::runtime_error(path + ": not a PNG");
  auto be32 = [&](size_t at) {
    return uint32_t(uint8_t(f[at])) << 24 | uint32_t(uint8_t(f[at + 1])) << 16 |
           uint32_t(uint8_t(f[at + 2])) << 8 | uint32_t(uint8_t(f[at + 3]));
  };
  PngImage img;
  std::string idat;
  bool ihdr = false, iend = false;
  for (size_t at = 8; at + 12 <= f.size() && !iend;) {
    const uint32_t len = be32(at);
    const std::string type = f.substr(at + 4, 4);
    if (at + 12 + len > f.size()) throw std::runtime_error(path + ": truncated chunk " + type);
    if (type == "IHDR") {
      img.width = be32(at + 8);
      img.height = be32(at + 12);
      const int depth = uint8_t(f[at + 16]), color = uint8_t(f[at + 17]), interlace = uint8_t(f[at + 20]);
      if (depth != 8 || (color != 2 && color != 6) || interlace != 0)
        throw std::runtime_error(path + ": unsupported PNG layout");
      img.channels = color == 6 ? 4 : 3;
      ihdr = true;
    } else if (type == "IDAT") {
      idat += f.substr(at + 8, len);
    } else if (type == "IEND") {
      iend = true;
    }
    at += 12 + len;
  }
  if (!ihdr || !iend || idat.empty()) throw std::runtime_error(path + ": missing IHDR, IDAT or IEND");
  const size_t stride = size_t(img.width) * size_t(img.channels);
  std::vector<uint8_t> raw((stride + 1) * img.height);
  uLongf raw_len = static_cast<uLongf>(raw.size());
  if (uncompress(raw.data(), &raw_len, reinterpret_cast<const Bytef*>(idat.data()),
                 static_cast<uLong>(idat.size())) != Z_OK ||
      raw_len != raw.size())
    throw std::runtime_error(path + ": IDAT does not inflate to the image size");
  img.pixels.assign(stride * img.height, 0);
  const size_t bpp = size_t(img.channels);
  for (size_t y = 0; y < img.height; ++y) {
    const uint8_t filter = raw[y * (stride + 1)];
    const uint8_t* in = &raw[y * (stride + 1) + 1];
    uint8_t* out = &img.pixels[y * stride];
    const uint8_t* up = y ? &img.pixels[(y - 1) * stride] : nullptr;
    for (size_t i = 0; i < stride; ++i) {
      const int a = i >= bpp ? out[i - bpp] : 0, b = up ? up[i] : 0, c = (up && i >= bpp) ? up[i - bpp] : 0;
      int pred = 0;
      switch (filter) {
        case 0:
          pred = 0;
          break;
        case 1:
          pred = a;
          break;
        case 2:
          pred = b;
          break;
        case 3:
          pred = (a + b) / 2;
          break;
        case 4: {
          const int p = a + b - c, pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
          pred = (pa <= pb && pa <= pc) ? a : (pb <= pc ? b : c);
          break;
        }
        default:
          throw std::runtime_error(path + ": bad scanline filter");
      }
      out[i] = uint8_t(in[i] + pred);
    }
  }
  return img;
}

inline size_t distinct_colors(const PngImage& img) {
  std::set<uint32_t> c;
  for (uint32_t y = 0; y < img.height; ++y)
    for (uint32_t x = 0; x < img.width; ++x) c.insert(img.rgb(x, y));
  return c.size();
}

/// Longest run of dark pixels along one row or one column: the box of a PLplot axes is a straight
/// black line hundreds of pixels long. Cairo antialiases a thin line over two pixel rows (each
/// about half grey), so a pixel counts as dark when it and its neighbour below (right) together
/// cover at least half of a black pixel's darkness.
inline uint32_t longest_dark_line(const PngImage& img, bool horizontal) {
  auto darkness = [&](uint32_t x, uint32_t y) {
    const uint32_t v = img.rgb(x, y);
    return 765 - int((v >> 16 & 255) + (v >> 8 & 255) + (v & 255));
  };
  uint32_t best = 0;
  const uint32_t outer = horizontal ? img.height : img.width, inner = horizontal ? img.width : img.height;
  for (uint32_t o = 0; o + 1 < outer; ++o) {
    uint32_t run = 0;
    for (uint32_t i = 0; i < inner; ++i) {
      const int d = horizontal ? darkness(i, o) + darkness(i, o + 1) : darkness(o, i) + darkness(o + 1, i);
      run = d >= 400 ? run + 1 : 0;
      best = std::max(best, run);
    }
  }
  return best;
}

/// Parses an SVG file as XML; returns the number of elements named `element` (e.g. "path").
inline int svg_count(const std::string& path, const std::string& element, std::string& root_name) {
  TiXmlDocument doc;
  const std::string text = read_binary(path);
  doc.Parse(text.c_str());
  if (doc.Error()) throw std::runtime_error(path + ": not well-formed XML: " + doc.ErrorDesc());
  const TiXmlElement* root = doc.RootElement();
  if (!root) throw std::runtime_error(path + ": no root element");
  root_name = root->Value();
  int n = 0;
  std::vector<const TiXmlElement*> stack{root};
  while (!stack.empty()) {
    const TiXmlElement* e = stack.back();
    stack.pop_back();
    if (element == e->Value()) ++n;
    for (const TiXmlElement* c = e->FirstChildElement(); c; c = c->NextSiblingElement()) stack.push_back(c);
  }
  return n;
}

}  // namespace ffsr::test
