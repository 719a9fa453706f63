#include "terrain/height_field.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "terrain/diamond_square.h"
#include "terrain/fractal.h"

namespace sylva::terrain {
namespace {

constexpr int kMaxResolution = 8193;
constexpr double kMaxLattice = 16777216.0;  // 2^24

Diagnostic InputError(std::string message) {
  Diagnostic d;
  d.message = std::move(message);
  return d;
}

Diagnostic OutOfRange(const char* field, double v, const char* range) {
  char buf[200];
  std::snprintf(buf, sizeof buf, "TerrainDef.%s %.10g is outside %s", field, v, range);
  return InputError(buf);
}

double PhysicalMemoryBytes() {
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
  if (pages <= 0 || page <= 0) return 0x1p62;  // unknown: no limit
  return double(pages) * double(page);
}

// A kRuntime diagnostic when `bytes` would take more than half the memory.
Status CheckFits(const char* what, double bytes) {
  const double limit = PhysicalMemoryBytes() / 2;
  if (bytes <= limit) return {};
  char buf[200];
  std::snprintf(buf, sizeof buf, "%s would take %.3g GB, more than half of this machine's %.3g GB",
                what, bytes / 1e9, 2 * limit / 1e9);
  Diagnostic d = InputError(buf);
  d.kind = ErrorKind::kRuntime;
  return d;
}

double FeatureSize(const TerrainDef& def) {
  return def.featureSize > 0 ? def.featureSize : std::max(def.sizeX, def.sizeZ) / 2;
}

size_t EditDistance(std::string_view a, std::string_view b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diag = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] != b[j - 1] ? 1u : 0u)});
      diag = up;
    }
  }
  return row[b.size()];
}

}  // namespace

const char* NameOf(NoiseKind kind) {
  switch (kind) {
    case NoiseKind::kFbm:
      return "fbm";
    case NoiseKind::kRidged:
      return "ridged";
    case NoiseKind::kDiamondSquare:
      return "diamond-square";
    case NoiseKind::kFlat:
      return "flat";
  }
  return "?";
}

Expected<NoiseKind> NoiseKindFromName(std::string_view name) {
  const NoiseKind kinds[] = {NoiseKind::kFbm, NoiseKind::kRidged, NoiseKind::kDiamondSquare,
                             NoiseKind::kFlat};
  const char* closest = nullptr;
  size_t best = 3;  // suggest only names within two edits
  for (NoiseKind k : kinds) {
    if (name == NameOf(k)) return k;
    const size_t d = EditDistance(name, NameOf(k));
    if (d < best) best = d, closest = NameOf(k);
  }
  std::string message = "unknown noise '" + std::string(name) + "'";
  if (closest) message += std::string("; did you mean '") + closest + "'?";
  message += " (fbm, ridged, diamond-square, flat)";
  return InputError(message);
}

Status Validate(const TerrainDef& def) {
  if (!(def.sizeX >= 1e-3 && def.sizeX <= 1e6))
    return OutOfRange("sizeX", def.sizeX, "0.001..1e+06 m");
  if (!(def.sizeZ >= 1e-3 && def.sizeZ <= 1e6))
    return OutOfRange("sizeZ", def.sizeZ, "0.001..1e+06 m");
  if (!(def.resolution >= 2 && def.resolution <= kMaxResolution)) {
    return OutOfRange("resolution", def.resolution, "2..8193");
  }
  if (!(def.height >= 0 && def.height <= 1e5))
    return OutOfRange("height", def.height, "0..1e+05 m");
  const int kind = int(def.noise);
  if (!(kind >= 0 && kind <= int(NoiseKind::kFlat))) {
    return InputError("TerrainDef.noise " + std::to_string(kind) + " is not a noise kind");
  }
  if (!(def.octaves >= 1 && def.octaves <= 16)) return OutOfRange("octaves", def.octaves, "1..16");
  if (!(def.lacunarity >= 1 && def.lacunarity <= 16)) {
    return OutOfRange("lacunarity", def.lacunarity, "1..16");
  }
  if (!(def.gain >= 0 && def.gain <= 1)) return OutOfRange("gain", def.gain, "0..1");
  if (!(def.featureSize == 0 || (def.featureSize >= 1e-3 && def.featureSize <= 1e7))) {
    return OutOfRange("featureSize", def.featureSize, "0 (auto) or 0.001..1e+07 m");
  }
  const int n = def.resolution;
  if (def.noise == NoiseKind::kDiamondSquare && ((n - 1) & (n - 2)) != 0) {
    return InputError("TerrainDef.resolution " + std::to_string(n) +
                      " is not 2^k + 1, as diamond-square needs (e.g. 129, 257, 513)");
  }
  if (def.noise == NoiseKind::kFbm || def.noise == NoiseKind::kRidged) {
    const double finest = std::max(def.sizeX, def.sizeZ) / 2 / FeatureSize(def) *
                          std::pow(def.lacunarity, def.octaves - 1);
    if (!(finest <= kMaxLattice)) {
      char buf[240];
      std::snprintf(buf, sizeof buf,
                    "TerrainDef: %d octaves of lacunarity %g over %g m with feature size %g m put "
                    "the finest octave's lattice coordinates at %.3g, past 2^24 (a float has no "
                    "fraction left there)",
                    def.octaves, def.lacunarity, std::max(def.sizeX, def.sizeZ), FeatureSize(def),
                    finest);
      return InputError(buf);
    }
  }
  return {};
}

Expected<HeightField> HeightField::Create(const TerrainDef& def, ThreadPool* pool) {
  if (Status st = Validate(def); !st.ok()) return st.error();
  const size_t n = size_t(def.resolution);
  if (Status st = CheckFits("the terrain's heights", double(n) * double(n) * sizeof(float));
      !st.ok()) {
    return st.error();
  }
  HeightField f;
  f.def_ = def;
  f.x0_ = -def.sizeX / 2;
  f.z0_ = -def.sizeZ / 2;
  f.dx_ = def.sizeX / double(n - 1);
  f.dz_ = def.sizeZ / double(n - 1);
  if (def.noise != NoiseKind::kDiamondSquare) f.heights_.assign(n * n, 0.0f);
  float* h = f.heights_.data();
  double scale = def.height;
  switch (def.noise) {
    case NoiseKind::kFbm:
    case NoiseKind::kRidged: {
      const double fs = FeatureSize(def);
      Grid2 grid;
      grid.x0 = float(f.x0_ / fs);
      grid.y0 = float(f.z0_ / fs);
      grid.dx = float(f.dx_ / fs);
      grid.dy = float(f.dz_ / fs);
      grid.nx = grid.ny = n;
      const FractalDef fd{def.octaves, float(def.lacunarity), float(def.gain)};
      if (def.noise == NoiseKind::kFbm) {
        Fbm2Grid(def.seed, fd, grid, h, BestKernel(), pool);
      } else {
        Ridged2Grid(def.seed, fd, grid, h, BestKernel(), pool);
      }
      break;
    }
    case NoiseKind::kDiamondSquare: {
      DiamondSquareDef dd;
      dd.size = def.resolution;
      dd.seed = def.seed;
      dd.roughness = float(def.gain);
      Expected<std::vector<float>> v = DiamondSquare(dd, pool);
      if (!v.ok()) return v.error();
      f.heights_ = std::move(*v);
      h = f.heights_.data();
      scale /= double(Bound(dd));
      break;
    }
    case NoiseKind::kFlat:
      scale = 0;
      break;
  }
  float lo = std::numeric_limits<float>::max(), hi = -lo;
  for (size_t k = 0; k < n * n; ++k) {
    h[k] = float(scale * double(h[k]));
    lo = std::min(lo, h[k]);
    hi = std::max(hi, h[k]);
  }
  f.minHeight_ = lo;
  f.maxHeight_ = hi;
  return f;
}

bool HeightField::Contains(double x, double z) const {
  return x >= x0_ && x <= -x0_ && z >= z0_ && z <= -z0_;
}

HeightField::Cell HeightField::Locate(double x, double z) const {
  const double last = double(def_.resolution - 1);
  const double gu = std::clamp((x - x0_) / dx_, 0.0, last);
  const double gw = std::clamp((z - z0_) / dz_, 0.0, last);
  const size_t i = std::min(size_t(gu), size_t(def_.resolution - 2));
  const size_t j = std::min(size_t(gw), size_t(def_.resolution - 2));
  return {i, j, gu - double(i), gw - double(j)};
}

double HeightField::Height(double x, double z) const {
  if (std::isnan(x) || std::isnan(z)) return std::numeric_limits<double>::quiet_NaN();
  const Cell c = Locate(x, z);
  const int i = int(c.i), j = int(c.j);
  const double h00 = HeightAt(i, j), h10 = HeightAt(i + 1, j);
  const double h01 = HeightAt(i, j + 1), h11 = HeightAt(i + 1, j + 1);
  if (c.u <= c.w) return h00 + c.u * (h11 - h01) + c.w * (h01 - h00);  // triangle A
  return h00 + c.u * (h10 - h00) + c.w * (h11 - h10);                  // triangle B
}

Vec3 HeightField::Normal(double x, double z) const {
  if (std::isnan(x) || std::isnan(z))
    return Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
  const Cell c = Locate(x, z);
  const int i = int(c.i), j = int(c.j);
  const double h00 = HeightAt(i, j), h10 = HeightAt(i + 1, j);
  const double h01 = HeightAt(i, j + 1), h11 = HeightAt(i + 1, j + 1);
  const bool a = c.u <= c.w;
  const double dhdu = a ? h11 - h01 : h10 - h00;
  const double dhdw = a ? h01 - h00 : h11 - h10;
  return Vec3(-dhdu / dx_, 1.0, -dhdw / dz_).normalized();
}

Expected<TerrainMesh> HeightField::MakeMesh() const {
  const size_t n = size_t(def_.resolution);
  const double bytes = double(n) * double(n) * 6 * sizeof(float) +
                       double(n - 1) * double(n - 1) * 6 * sizeof(uint32_t);
  if (Status st = CheckFits("the terrain's mesh", bytes); !st.ok()) return st.error();
  TerrainMesh m;
  m.positions.resize(n * n * 3);
  m.normals.resize(n * n * 3);
  m.indices.reserve((n - 1) * (n - 1) * 6);
  for (size_t j = 0; j < n; ++j) {
    const size_t jm = j > 0 ? j - 1 : j, jp = j + 1 < n ? j + 1 : j;
    for (size_t i = 0; i < n; ++i) {
      const size_t im = i > 0 ? i - 1 : i, ip = i + 1 < n ? i + 1 : i;
      const size_t v = j * n + i;
      m.positions[3 * v + 0] = float(VertexX(int(i)));
      m.positions[3 * v + 1] = heights_[v];
      m.positions[3 * v + 2] = float(VertexZ(int(j)));
      const double dhdx =
          (double(heights_[j * n + ip]) - double(heights_[j * n + im])) / (double(ip - im) * dx_);
      const double dhdz =
          (double(heights_[jp * n + i]) - double(heights_[jm * n + i])) / (double(jp - jm) * dz_);
      const Vec3 nrm = Vec3(-dhdx, 1.0, -dhdz).normalized();
      m.normals[3 * v + 0] = float(nrm.x());
      m.normals[3 * v + 1] = float(nrm.y());
      m.normals[3 * v + 2] = float(nrm.z());
    }
  }
  for (size_t j = 0; j + 1 < n; ++j) {
    for (size_t i = 0; i + 1 < n; ++i) {
      const uint32_t v00 = uint32_t(j * n + i), v10 = v00 + 1;
      const uint32_t v01 = uint32_t(v00 + n), v11 = v01 + 1;
      m.indices.insert(m.indices.end(), {v00, v01, v11, v00, v11, v10});
    }
  }
  return m;
}

}  // namespace sylva::terrain
