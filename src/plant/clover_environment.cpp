#include "plant/clover_environment.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace sylva::plant {
namespace {

uint32_t Be16(const unsigned char* p) {
  return uint32_t(p[0]) << 8 | p[1];
}
uint32_t Be32(const unsigned char* p) {
  return uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | p[3];
}

Diagnostic ImageError(const std::string& path, const std::string& what) {
  Diagnostic d;
  d.loc.file = path;
  d.message = "cannot read the image " + path + ": " + what;
  return d;
}

// SGI image format (Paul Haeberli, "The SGI Image File Format", 1.0): a
// 512-byte big-endian header, then channels of rows from the bottom,
// verbatim or run-length encoded with a table of row offsets.
Expected<CloverImage> ReadSgi(const std::string& bytes, const std::string& path) {
  const auto* p = reinterpret_cast<const unsigned char*>(bytes.data());
  const size_t n = bytes.size();
  if (n < 512) return ImageError(path, "shorter than an SGI header");
  const int storage = p[2], bpc = p[3];
  const int xsize = int(Be16(p + 6)), ysize = int(Be16(p + 8));
  const int zsize = std::max(1, int(Be16(p + 10)));
  if (bpc != 1) return ImageError(path, "only 8 bits per channel are read");
  if (xsize <= 0 || ysize <= 0) return ImageError(path, "no pixels");
  CloverImage img;
  img.width = xsize;
  img.height = ysize;
  auto channel = [&](int z, std::vector<uint8_t>& out) -> std::optional<Diagnostic> {
    z = std::min(z, zsize - 1);  // a grey image gives its one channel
    out.assign(size_t(xsize) * size_t(ysize), 0);
    for (int y = 0; y < ysize; ++y) {
      uint8_t* row = out.data() + size_t(y) * size_t(xsize);
      if (storage == 0) {
        const size_t at = 512 + (size_t(z) * size_t(ysize) + size_t(y)) * size_t(xsize);
        if (at + size_t(xsize) > n) return ImageError(path, "truncated");
        std::copy(p + at, p + at + xsize, row);
        continue;
      }
      const size_t tab = size_t(ysize) * size_t(zsize);
      if (512 + 8 * tab > n) return ImageError(path, "truncated offset table");
      const size_t k = size_t(z) * size_t(ysize) + size_t(y);
      size_t at = Be32(p + 512 + 4 * k);
      const size_t end = std::min(n, at + Be32(p + 512 + 4 * tab + 4 * k));
      int x = 0;
      while (at < end) {
        const unsigned char c = p[at++];
        const int count = c & 0x7f;
        if (count == 0) break;
        if (x + count > xsize) return ImageError(path, "a run passes the row's end");
        if (c & 0x80) {
          if (at + size_t(count) > end) return ImageError(path, "truncated run");
          std::copy(p + at, p + at + count, row + x);
          at += size_t(count);
        } else {
          if (at >= end) return ImageError(path, "truncated run");
          std::fill(row + x, row + x + count, p[at++]);
        }
        x += count;
      }
    }
    return std::nullopt;
  };
  if (auto e = channel(0, img.red)) return *e;
  if (auto e = channel(1, img.green)) return *e;
  return img;
}

}  // namespace

Expected<CloverImage> ReadCloverImage(const std::string& bytes, const std::string& path) {
  if (bytes.size() >= 2 && Be16(reinterpret_cast<const unsigned char*>(bytes.data())) == 474)
    return ReadSgi(bytes, path);
  return ImageError(path,
                    "not an SGI image (clover's .rgb); Sylva reads no other image format here");
}

CloverEnvironment::CloverEnvironment(const CloverDef& def, const CloverImage* image,
                                     int coordinates)
    : def_(def), coordinates_(coordinates) {
  const size_t cells = size_t(def_.size[0]) * size_t(def_.size[1]);
  light_.assign(cells, 255);
  ratio_.assign(cells, 0);
  objects_.assign(cells, 0);
  if (image && image->width > 0 && image->height > 0) {
    // Each cell takes the pixel at (x * xratio, y * yratio), as clover does.
    const float xr = def_.size[0] > 1 ? float(image->width - 1) / float(def_.size[0] - 1) : 0;
    const float yr = def_.size[1] > 1 ? float(image->height - 1) / float(def_.size[1] - 1) : 0;
    for (int y = 0; y < def_.size[1]; ++y) {
      const size_t iy = size_t(std::min(image->height - 1, int(float(y) * yr)));
      for (int x = 0; x < def_.size[0]; ++x) {
        const size_t ix = size_t(std::min(image->width - 1, int(float(x) * xr)));
        const size_t c = size_t(y) * size_t(def_.size[0]) + size_t(x);
        light_[c] = image->green[iy * size_t(image->width) + ix];
        ratio_[c] = image->red[iy * size_t(image->width) + ix];
      }
    }
  }
  powers_[0] = 1.0f;
  for (int i = 1; i < 256; ++i) powers_[i] = def_.transmittance * powers_[i - 1];
}

int64_t CloverEnvironment::CellOf(float x, float y) const {
  const float fx = std::floor((x - def_.pos[0]) / def_.range[0] * float(def_.size[0]));
  const float fy = std::floor((y - def_.pos[1]) / def_.range[1] * float(def_.size[1]));
  if (!(fx >= 0 && fx < float(def_.size[0]) && fy >= 0 && fy < float(def_.size[1]))) return -1;
  return int64_t(fy) * def_.size[0] + int64_t(fx);
}

Status CloverEnvironment::Answer(std::span<EnvQuery> queries) {
  if (coordinates_ < (def_.zIsUp ? 2 : 3)) return {};  // clover: no position, no answer
  if (def_.removeOldLeaves) std::fill(objects_.begin(), objects_.end(), uint8_t(0));
  std::vector<EnvQuery*> asked;
  for (EnvQuery& q : queries) {
    const float x = float(q.position.x());
    const float y = float(def_.zIsUp ? q.position.y() : q.position.z());
    if (q.params.size() == 1 || q.params[0] == 0) {
      asked.push_back(&q);
      continue;
    }
    // Add (1) or remove (anything else) a leaf disc of area params[1].
    const int add = q.params[0] == 1 ? 1 : -1;
    const float area = float(q.params[1]);
    if (!(area >= 0.0000001f)) continue;
    const float radius = std::sqrt(area / float(M_PI));
    int node[2], r[2];
    const float at[2] = {x, y};
    bool far = false;
    for (int c = 0; c < 2; ++c) {
      const float f = std::floor((at[c] - def_.pos[c]) / def_.range[c] * float(def_.size[c]));
      const float rr = radius / def_.range[c] * float(def_.size[c]) + 1;
      // Positions or discs far off the grid touch none of it.
      if (!(std::abs(f) < 1e8f && rr < 1e8f)) far = true;
      node[c] = far ? 0 : int(f);
      r[c] = far ? 0 : int(rr);
    }
    if (far) continue;
    for (int dy = -r[1]; dy < r[1]; ++dy) {
      const int cy = node[1] + dy;
      if (cy < 0 || cy >= def_.size[1]) continue;
      for (int dx = -r[0]; dx < r[0]; ++dx) {
        const int cx = node[0] + dx;
        if (cx < 0 || cx >= def_.size[0]) continue;
        if (float(dx * dx) / float(r[0] * r[0]) + float(dy * dy) / float(r[1] * r[1]) > 1) continue;
        uint8_t& o = objects_[size_t(cy) * size_t(def_.size[0]) + size_t(cx)];
        if (add == 1 && o < 255) ++o;
        if (add == -1 && o > 0) --o;
      }
    }
  }
  for (EnvQuery* q : asked) {
    const int64_t c =
        CellOf(float(q->position.x()), float(def_.zIsUp ? q->position.y() : q->position.z()));
    // As the program computes it (in double) and sends it (a float).
    q->params[0] =
        c < 0 ? 0.0 : double(float(light_[size_t(c)] / 255.0 * powers_[objects_[size_t(c)]]));
    if (q->params.size() >= 2)
      q->params[1] = c < 0 ? 0.0 : double(float(ratio_[size_t(c)] / 128.0));
  }
  return {};
}

}  // namespace sylva::plant
