#include "mesh/screen_detail.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "core/parallel.h"
#include "mesh/tessellator.h"
#include "mesh/view_test_util.h"
#include "plant/plant_test_util.h"

namespace sylva::mesh {
namespace {

constexpr double kPi = 3.14159265358979323846;

using testing::LookAtPerspective;

Vec2 Pixel(const ScreenView& v, const Vec3& p) {
  const Vec4 c = v.viewProjection * Vec4(p.x(), p.y(), p.z(), 1);
  return Vec2((c.x() / c.w() * 0.5 + 0.5) * v.width, (0.5 - c.y() / c.w() * 0.5) * v.height);
}

TEST(ScreenDetail, SidesTableOfTheIssue) {
  const std::pair<double, int> table[] = {{1, 3},   {2, 5},   {4, 7},   {8, 9},
                                          {16, 13}, {32, 18}, {64, 26}, {128, 36}};
  for (auto [r, n] : table) {
    EXPECT_EQ(SidesForPixelRadius(r, 0.5), n) << "radius " << r << " px";
  }
  EXPECT_EQ(SidesForPixelRadius(0.01, 0.5), 3);
  EXPECT_EQ(SidesForPixelRadius(1e9, 0.5), 256);
  EXPECT_EQ(SidesForPixelRadius(std::nan(""), 0.5), 256);
  EXPECT_EQ(SidesForPixelRadius(std::numeric_limits<double>::infinity(), 0.5), 256);
}

TEST(ScreenDetail, SidesAreTheFewestWithinEps) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> logR(-1, 3.5), epsD(0.1, 2);
  for (int i = 0; i < 20000; ++i) {
    const double r = std::pow(10, logR(rng)), eps = epsD(rng);
    const int n = SidesForPixelRadius(r, eps);
    const double err = r * (1 - std::cos(kPi / n));
    if (n < 256) {
      EXPECT_LE(err, eps * (1 + 1e-9)) << "r " << r << " eps " << eps << " n " << n;
    }
    if (n > 3) {
      const double fewer = r * (1 - std::cos(kPi / (n - 1)));
      EXPECT_GT(fewer, eps) << "r " << r << " eps " << eps << ": " << n - 1 << " sides suffice";
    }
  }
}

// A random cylinder (one segment) under a random perspective camera,
// tessellated with screen-space detail: at both rings, the extent of the
// tessellated cross-section across the projected axis is compared with
// the true circle's (sampled finely). The difference is the silhouette error.
TEST(ScreenDetail, MeasuredSilhouetteErrorOfRandomCylindersStaysUnderEps) {
  std::mt19937_64 rng(2026);
  std::uniform_real_distribution<double> u(-1, 1), u01(0, 1);
  double worst = 0;
  int ribbons = 0, tubes = 0;
  for (int trial = 0; trial < 400; ++trial) {
    PlantGeometry g;
    Segment s;
    Vec3 axis(u(rng), u(rng), u(rng));
    if (axis.norm() < 0.1) axis = Vec3::UnitY();
    axis.normalize();
    const double len = 0.5 + 2 * u01(rng);
    s.start = Vec3(u(rng), u(rng), u(rng)) * 0.3;
    s.end = s.start + axis * len;
    s.left = axis.unitOrthogonal();
    const double radius = std::pow(10, -3 + 2.5 * u01(rng));
    s.radiusStart = float(radius);
    s.radiusEnd = float(radius * (0.5 + 0.5 * u01(rng)));
    g.segments.push_back(s);
    g.branchCount = 1;
    ScreenView view;
    view.width = 64 + int(1900 * u01(rng));
    view.height = 64 + int(1000 * u01(rng));
    view.eps = std::array<double, 3>{0.25, 0.5, 1.0}[trial % 3];
    Vec3 dir(u(rng), u(rng), u(rng));
    if (dir.norm() < 0.1) dir = Vec3::UnitZ();
    const Vec3 eye = dir.normalized() * (4 + 20 * u01(rng));
    view.viewProjection = LookAtPerspective(eye, Vec3(u(rng), u(rng), u(rng)) * 0.2,
                                            20 + 60 * u01(rng), double(view.width) / view.height);
    TessellateOptions opt;
    opt.view = view;
    opt.cull = false;
    TriangleMesh m;
    ASSERT_TRUE(Tessellate(g, opt, m).ok());
    ASSERT_GT(m.vertexCount(), 0u);
    const bool ribbon = m.vertexCount() == 4;
    (ribbon ? ribbons : tubes)++;
    const size_t ring = ribbon ? 2 : (m.vertexCount() - 2 * 0) / 2;
    for (int end = 0; end < 2; ++end) {
      const Vec3 P = end ? s.end : s.start;
      const double R = end ? double(s.radiusEnd) : double(s.radiusStart);
      // The screen direction across the projected axis.
      const Vec2 a = Pixel(view, s.start), b = Pixel(view, s.end);
      Vec2 across(-(b - a).y(), (b - a).x());
      if (across.norm() < 1e-9) continue;  // seen end-on: no side silhouette
      across.normalize();
      const Vec3 N = axis.unitOrthogonal(), B = axis.cross(N);
      double cMax = -1e300, cMin = 1e300;
      for (int k = 0; k < 4096; ++k) {
        const double th = 2 * kPi * k / 4096;
        const double q = across.dot(Pixel(view, P + R * (N * std::cos(th) + B * std::sin(th))));
        cMax = std::max(cMax, q);
        cMin = std::min(cMin, q);
      }
      // The ring's vertices: tubes without caps have (S + 1) per ring, two
      // rings; with caps the rings come first as well.
      const size_t first = end ? ring : 0;
      const size_t count = ribbon ? 2 : 0;
      double pMax = -1e300, pMin = 1e300;
      if (ribbon) {
        for (size_t k = first; k < first + count; ++k) {
          const double q = across.dot(Pixel(view, m.positions[k].cast<double>()));
          pMax = std::max(pMax, q);
          pMin = std::min(pMin, q);
        }
      } else {
        // Ring vertices are those at distance R from P across the axis.
        for (const Vec3f& pf : m.positions) {
          const Vec3 p = pf.cast<double>();
          const Vec3 d = p - P;
          if (std::abs(d.dot(axis)) > 1e-5 * (1 + len)) continue;
          if (std::abs(d.norm() - R) > 1e-4 * R + 1e-6) continue;
          const double q = across.dot(Pixel(view, p));
          pMax = std::max(pMax, q);
          pMin = std::min(pMin, q);
        }
      }
      ASSERT_LT(pMin, 1e300) << "no ring vertices found, trial " << trial;
      const double err = std::max(std::abs(cMax - pMax), std::abs(cMin - pMin));
      worst = std::max(worst, err / view.eps);
      EXPECT_LE(err, view.eps) << "trial " << trial << " end " << end << ": radius "
                               << R * PixelsPerUnit(view, P) << " px, " << m.vertexCount()
                               << " vertices";
    }
  }
  EXPECT_GT(ribbons, 20) << "the trials should cover ribbons";
  EXPECT_GT(tubes, 20) << "the trials should cover tubes";
  RecordProperty("worst_error_over_eps", std::to_string(worst));
}

TEST(ScreenDetail, HierarchyKeepsEveryBoxThatMeetsTheFrustum) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-30, 30), size(0.01, 3);
  std::vector<Box> boxes(5000);
  for (Box& b : boxes) {
    const Vec3 c(u(rng), u(rng), u(rng));
    b.Add(c);
    b.Add(c + Vec3(size(rng), size(rng), size(rng)));
  }
  boxes[17].lo.y() = std::nan("");  // unbounded boxes are kept
  const BoundingHierarchy h(boxes);
  const Frustum f =
      Frustum::FromViewProjection(LookAtPerspective(Vec3(0, 5, 40), Vec3(3, 0, 0), 30, 16.0 / 9));
  const auto visible = h.Visible(f);
  size_t kept = 0, outside = 0;
  for (size_t i = 0; i < boxes.size(); ++i) {
    if (i == 17) {
      EXPECT_TRUE(visible[i]);
      continue;
    }
    const bool out = f.Classify(boxes[i]) == Frustum::Side::kOutside;
    if (!out) {
      EXPECT_TRUE(visible[i]) << "box " << i << " meets the frustum but was culled";
    }
    outside += out;
    kept += visible[i];
  }
  EXPECT_GT(outside, 1000u);
  EXPECT_LT(kept, boxes.size() - outside / 2) << "the hierarchy culls too little";
}

TEST(ScreenDetail, SameTrianglesForAnyThreadCount) {
  auto p = testing::PlantFromFile("abop/fig2_06a_monopodial.lsys", 12, plant::Stage::kGeometry);
  ASSERT_TRUE(p);
  ScreenView view;
  view.width = 960;
  view.height = 540;
  view.viewProjection = LookAtPerspective(Vec3(2, 3, 4), Vec3(0, 2.5, 0), 35, 960.0 / 540);
  auto hash = [](const TriangleMesh& m) {
    uint64_t h = 1469598103934665603ull;
    auto mix = [&](const void* data, size_t bytes) {
      const auto* c = static_cast<const unsigned char*>(data);
      for (size_t i = 0; i < bytes; ++i) h = (h ^ c[i]) * 1099511628211ull;
    };
    mix(m.positions.data(), m.positions.size() * sizeof(Vec3f));
    mix(m.normals.data(), m.normals.size() * sizeof(Vec3f));
    mix(m.uvs.data(), m.uvs.size() * sizeof(Vec2f));
    mix(m.indices.data(), m.indices.size() * 4);
    mix(m.material.data(), m.material.size() * 2);
    mix(m.coverage.data(), m.coverage.size() * 4);
    return h;
  };
  // Plain, and with coverage lines and a history carried from a farther frame.
  for (bool coverage : {false, true}) {
    uint64_t first = 0;
    size_t triangles = 0;
    for (int threads : {1, 2, 3, 8}) {
      ThreadPool pool(threads);
      TessellateOptions opt;
      opt.view = view;
      opt.view->coverage = coverage;
      opt.pool = threads > 1 ? &pool : nullptr;
      DetailHistory history;
      TriangleMesh m;
      if (coverage) {
        opt.history = &history;
        opt.view->viewProjection =
            LookAtPerspective(Vec3(2.2, 3, 4.4), Vec3(0, 2.5, 0), 35, 960.0 / 540);
        ASSERT_TRUE(Tessellate(p->geometry, opt, m).ok());
        m.Clear();
        opt.view->viewProjection = view.viewProjection;
      }
      ASSERT_TRUE(Tessellate(p->geometry, opt, m).ok());
      if (threads == 1) {
        first = hash(m);
        triangles = m.triangleCount();
        EXPECT_EQ(m.coverage.size(), coverage ? m.vertexCount() : 0u);
        EXPECT_EQ(Validate(m), "");
      }
      EXPECT_EQ(hash(m), first) << threads << " threads, coverage " << coverage;
      EXPECT_EQ(m.triangleCount(), triangles) << threads << " threads";
    }
    EXPECT_GT(triangles, 1000u);
  }
}

// The levels are ordered as the projected radius: a coverage line under
// half a pixel (only with coverage), a ribbon under 3 eps, then the sides.
// With hysteresis a level is never coarser than the radius needs, and a
// finer one is kept until the radius is kHysteresis below its threshold.
TEST(ScreenDetail, LevelsAndHysteresis) {
  EXPECT_EQ(ChainLevel(0.3, 0.5, true), 0);
  EXPECT_EQ(ChainLevel(0.3, 0.5, false), 1);
  EXPECT_EQ(ChainLevel(1.4, 0.5, true), 1);
  EXPECT_EQ(ChainLevel(1.6, 0.5, true), SidesForPixelRadius(1.6, 0.5));
  EXPECT_EQ(ChainLevel(std::nan(""), 0.5, true), 256);
  int prev = 0;
  for (double r = 0.01; r < 300; r *= 1.01) {
    const int l = ChainLevel(r, 0.5, true);
    ASSERT_GE(l, prev) << "the level should grow with the radius, at r = " << r;
    prev = l;
    const int fine = ChainLevel(r * 1.3, 0.5, true);
    // From a finer level: kept within the margin, never coarser than needed.
    const int kept = ChainLevelAfter(fine, r, 0.5, true);
    EXPECT_GE(kept, l) << "r = " << r;
    EXPECT_LE(kept, std::max(l, ChainLevel(r * (1 + kHysteresis), 0.5, true))) << "r = " << r;
    // From a coarser level: raised to what the radius needs at once.
    EXPECT_EQ(ChainLevelAfter(0, r, 0.5, true), l) << "r = " << r;
    EXPECT_EQ(ChainLevelAfter(-1, r, 0.5, true), l) << "r = " << r;
  }
  // Just under the ribbon threshold (1.5 px) a tube stays a tube, and a
  // line stays a line just over half a pixel.
  EXPECT_EQ(ChainLevelAfter(3, 1.45, 0.5, true), 3);
  EXPECT_EQ(ChainLevelAfter(3, 1.2, 0.5, true), 1);
  EXPECT_EQ(ChainLevelAfter(0, 0.52, 0.5, true), 1) << "a coarser level is never kept";
  EXPECT_EQ(ChainLevelAfter(1, 0.45, 0.5, true), 1);
  EXPECT_EQ(ChainLevelAfter(1, 0.4, 0.5, true), 0);
}

// With coverage, a leaf (polygon) under a pixel becomes a one-pixel quad
// whose coverage is its projected area in square pixels; a larger one
// stays a polygon. A twig under a pixel becomes a line kLinePixels wide.
TEST(ScreenDetail, SubPixelLeavesBecomePointsAndTwigsLines) {
  ScreenView view;
  view.width = 960;
  view.height = 540;
  view.viewProjection = LookAtPerspective(Vec3(0, 0, 10), Vec3(0, 0, 0), 35, 960.0 / 540);
  view.coverage = true;
  const double ppu = PixelsPerUnit(view, Vec3::Zero());
  PlantGeometry g;
  for (double side : {0.5, 4.0}) {  // pixels
    Polygon poly;
    const double h = side / ppu / 2;
    poly.vertices = {Vec3(-h, -h, 0), Vec3(h, -h, 0), Vec3(h, h, 0), Vec3(-h, h, 0)};
    poly.color = 3;
    g.polygons.push_back(poly);
  }
  Segment s;
  s.start = Vec3(1, -1, 0);
  s.end = Vec3(1, 1, 0);
  s.radiusStart = s.radiusEnd = float(0.1 / ppu);  // 0.2 px wide
  s.left = Vec3(1, 0, 0);
  g.segments.push_back(s);
  g.branchCount = 1;
  TessellateOptions opt;
  opt.view = view;
  TriangleMesh m;
  ASSERT_TRUE(Tessellate(g, opt, m).ok());
  EXPECT_EQ(Validate(m), "");
  ASSERT_EQ(m.coverage.size(), m.vertexCount());
  // The twig: 4 vertices (a line), then the point (4), then the 4 px square (4).
  ASSERT_EQ(m.vertexCount(), 12u);
  EXPECT_EQ(m.triangleCount(), 6u);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(m.coverage[i], 0.2, 0.01) << "twig vertex " << i;
  const double width = (m.positions[1] - m.positions[0]).norm() * ppu;
  EXPECT_NEAR(width, kLinePixels, 0.02) << "the line's drawn width in pixels";
  for (int i = 4; i < 8; ++i) {
    EXPECT_NEAR(m.coverage[i], 0.25, 0.01) << "a 0.5 px square covers a quarter of a pixel";
  }
  EXPECT_NEAR((m.positions[6] - m.positions[4]).norm() * ppu, std::sqrt(2.0) * kLinePixels, 0.02)
      << "the point's diagonal in pixels";
  for (int i = 8; i < 12; ++i) EXPECT_EQ(m.coverage[i], 1.0f) << "the 4 px square is opaque";
  EXPECT_EQ(m.material[2], 3) << "the point keeps the leaf's colour";
  // Without coverage (export): the leaf stays a polygon and the twig a ribbon, opaque.
  opt.view->coverage = false;
  TriangleMesh plain;
  ASSERT_TRUE(Tessellate(g, opt, plain).ok());
  EXPECT_TRUE(plain.coverage.empty());
  EXPECT_NEAR((plain.positions[1] - plain.positions[0]).norm() * ppu, 0.2, 0.01);
}

TEST(TriangleMesh, CoverageIsValidatedAndAppended) {
  TriangleMesh a;
  a.positions = {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(0, 1, 0)};
  a.normals.assign(3, Vec3f(0, 0, 1));
  a.uvs.assign(3, Vec2f(0, 0));
  a.indices = {0, 1, 2};
  a.material = {0};
  TriangleMesh b = a;
  b.coverage = {0.5f, 0.5f, 0.5f};
  TriangleMesh c = a;
  c.Append(b);
  ASSERT_EQ(c.coverage.size(), 6u);
  EXPECT_EQ(c.coverage[0], 1.0f);
  EXPECT_EQ(c.coverage[5], 0.5f);
  EXPECT_EQ(Validate(c), "");
  c.coverage[4] = std::nanf("");
  EXPECT_NE(Validate(c).find("coverage 4"), std::string::npos) << Validate(c);
  EXPECT_NE(FindNonFinite(c), "");
  c.coverage[4] = 0;
  EXPECT_NE(Validate(c).find("outside (0, 1]"), std::string::npos) << Validate(c);
  c.coverage.pop_back();
  EXPECT_NE(Validate(c), "");
}

TEST(ScreenDetail, FewerTrianglesThanUniformSixteenSidesAtOnePixelTwigs) {
  auto p = testing::PlantFromFile("abop/fig2_06a_monopodial.lsys", 14, plant::Stage::kGeometry);
  ASSERT_TRUE(p);
  ScreenView view;
  view.width = 960;
  view.height = 540;
  view.viewProjection = LookAtPerspective(Vec3(6, 5, 12), Vec3(0, 4, 0), 35, 960.0 / 540);
  TessellateOptions lod, uniform;
  lod.view = view;
  uniform.detail.sides = 16;
  TriangleMesh a, b;
  ASSERT_TRUE(Tessellate(p->geometry, lod, a).ok());
  ASSERT_TRUE(Tessellate(p->geometry, uniform, b).ok());
  EXPECT_LT(double(a.triangleCount()), 0.1 * double(b.triangleCount()))
      << a.triangleCount() << " screen-space vs " << b.triangleCount() << " uniform";
}

// Rings along a chain: a straight chain of equal radius keeps two; a bent
// one keeps more the larger it is on screen, and every joint it drops lies
// within eps/2 pixels of the tube that replaces it.
TEST(ScreenDetail, RingsFollowCurvatureAndProjectedSize) {
  auto chain = [](bool bent) {
    PlantGeometry g;
    const int n = 64;
    auto at = [&](int k) {
      const double a = 0.5 * kPi * k / n;
      return bent ? Vec3(std::cos(a) - 1, std::sin(a), 0) : Vec3(0, double(k) / n, 0);
    };
    for (int k = 0; k < n; ++k) {
      Segment s;
      s.start = at(k);
      s.end = at(k + 1);
      s.left = Vec3(0, 0, 1);
      s.radiusStart = s.radiusEnd = 0.05f;
      g.segments.push_back(s);
    }
    g.branchCount = 1;
    return g;
  };
  auto rings = [&](const PlantGeometry& g, double distance, double* worst) {
    ScreenView view;
    view.viewProjection =
        LookAtPerspective(Vec3(-0.5, 0.5, distance), Vec3(-0.5, 0.5, 0), 40, 960.0 / 540);
    TessellateOptions opt;
    opt.view = view;
    TriangleMesh m;
    EXPECT_TRUE(Tessellate(g, opt, m).ok());
    // Sides S and rings K from the counts: 2 S K triangles (caps
    // included), (K + 2)(S + 1) vertices.
    int S = 0;
    for (int t = 3; t <= 256 && !S; ++t) {
      const size_t K = m.triangleCount() / size_t(2 * t);
      if (m.triangleCount() == K * size_t(2 * t) && m.vertexCount() == (K + 2) * size_t(t + 1))
        S = t;
    }
    EXPECT_GT(S, 0) << "not a capped tube: " << m.vertexCount() << " vertices";
    if (!S) return size_t(0);
    // Ring centres: the mean of each ring's S vertices (the seam repeats the first).
    const size_t ring = size_t(S + 1);
    std::vector<Vec3> centres;
    for (size_t r = 0; (r + 1) * ring <= m.vertexCount() - 2 * ring; ++r) {
      Vec3 c = Vec3::Zero();
      for (int j = 0; j < S; ++j) c += m.positions[r * ring + size_t(j)].cast<double>();
      centres.push_back(c / S);
    }
    *worst = 0;
    for (const Segment& s : g.segments) {  // every joint against the nearest kept span
      double best = 1e300;
      for (size_t k = 0; k + 1 < centres.size(); ++k) {
        const Vec3 d = centres[k + 1] - centres[k], q = s.end - centres[k];
        const double t = std::clamp(q.dot(d) / d.dot(d), 0.0, 1.0);
        best = std::min(best, (q - t * d).norm() * PixelsPerUnit(view, s.end));
      }
      *worst = std::max(*worst, best);
    }
    return centres.size();
  };
  double worst = 0;
  EXPECT_EQ(rings(chain(false), 3, &worst), 2u) << "a straight chain needs two rings";
  const size_t far = rings(chain(true), 10, &worst);
  EXPECT_LE(worst, 0.25 + 0.01) << "far: a dropped joint is " << worst << " px off";
  const size_t near = rings(chain(true), 2, &worst);
  EXPECT_LE(worst, 0.25 + 0.01) << "near: a dropped joint is " << worst << " px off";
  EXPECT_LT(far, near) << "rings far " << far << ", near " << near;
  EXPECT_LT(near, 65u) << "even near, a smooth arc should drop some joints";
  EXPECT_GT(far, 2u) << "the arc's bend shows even far away";
  RecordProperty("rings", std::to_string(far) + " far, " + std::to_string(near) + " near");
}

TEST(ScreenDetail, BoundsHoldEveryVertexAtAnyDetail) {
  auto p = testing::PlantFromFile("abop/fig2_06a_monopodial.lsys", 8, plant::Stage::kGeometry);
  ASSERT_TRUE(p);
  const Box box = TessellatedBounds(p->geometry, nullptr);
  TessellateOptions opt;
  opt.detail.sides = 64;
  TriangleMesh m;
  ASSERT_TRUE(Tessellate(p->geometry, opt, m).ok());
  Box mb;
  for (const Vec3f& v : m.positions) mb.Add(v.cast<double>());
  for (int k = 0; k < 3; ++k) {
    EXPECT_LE(box.lo[k], mb.lo[k] + 1e-5) << "axis " << k;
    EXPECT_GE(box.hi[k], mb.hi[k] - 1e-5) << "axis " << k;
    EXPECT_NEAR(box.lo[k], mb.lo[k], 0.01) << "axis " << k << ": the box should be tight";
    EXPECT_NEAR(box.hi[k], mb.hi[k], 0.01) << "axis " << k << ": the box should be tight";
  }
}

}  // namespace
}  // namespace sylva::mesh

namespace sylva::plant {
namespace {

TEST(PlantSpec, BadScreenViewIsReported) {
  PlantSpec spec;
  spec.path = "x.lsys";
  spec.view = mesh::ScreenView{};
  EXPECT_TRUE(Validate(spec).items.empty()) << Validate(spec).FormatAll();
  spec.view->eps = 0;
  spec.view->width = 0;
  spec.view->viewProjection(2, 1) = std::nan("");
  const DiagnosticList list = Validate(spec);
  ASSERT_EQ(list.items.size(), 3u) << list.FormatAll();
  EXPECT_NE(list.items[0].message.find("lod eps"), std::string::npos) << list.FormatAll();
  EXPECT_NE(list.items[1].message.find("viewport 0x540"), std::string::npos) << list.FormatAll();
  EXPECT_NE(list.items[2].message.find("non-finite"), std::string::npos) << list.FormatAll();
}

}  // namespace
}  // namespace sylva::plant

namespace sylva::mesh {
namespace {

// Without popping, along a curved branch: a slow dolly toward arcs of
// several curvatures that wobbles (three steps of 3 % in, one back out)
// changes each chain's ring count only one way with the history, and
// never to fewer rings than the tolerance eps / 2 needs. Without the
// history some chains flip back and forth, so the test can fail.
TEST(ScreenDetail, SlowDollyDoesNotFlipRingSpacingBackAndForth) {
  PlantGeometry g;
  const int kArcs = 6, kSegments = 240;
  for (int a = 0; a < kArcs; ++a) {
    const double bend = 0.5 + 0.4 * a;  // radius of the arc
    const Vec3 centre(-6 + 2.2 * a, 0, 0);
    for (int k = 0; k < kSegments; ++k) {
      auto at = [&](int i) {
        const double phi = 1.5 * kPi * i / kSegments;
        return Vec3(centre + bend * Vec3(std::cos(phi), std::sin(phi), 0));
      };
      Segment s;
      s.start = at(k);
      s.end = at(k + 1);
      s.radiusStart = s.radiusEnd = 0.02f;
      s.left = Vec3(0, 0, 1);
      s.branch = uint32_t(a);
      g.segments.push_back(s);
    }
  }
  g.branchCount = kArcs;
  std::vector<double> distances;
  double d = 60;
  for (int k = 0; k < 64; ++k) {
    distances.push_back(d);
    d *= k % 4 == 3 ? 1 / 0.97 : 0.97;
  }
  auto run = [&](bool hysteresis) {
    DetailHistory history;
    std::vector<std::vector<uint16_t>> rings;
    for (double dist : distances) {
      TessellateOptions opt;
      opt.view = ScreenView{LookAtPerspective(Vec3(0, 0.3, dist), Vec3(0, 0, 0), 35, 960.0 / 540),
                            960, 540, 0.5};
      opt.history = &history;
      if (!hysteresis) history.level.clear();  // a reset history: no hysteresis
      TriangleMesh m;
      EXPECT_TRUE(Tessellate(g, opt, m).ok());
      rings.push_back(history.rings);
    }
    return rings;
  };
  const auto with = run(true), without = run(false);
  ASSERT_EQ(with[0].size(), size_t(kArcs));
  auto count = [&](const std::vector<std::vector<uint16_t>>& r) {
    size_t reversals = 0, changes = 0;
    for (size_t c = 0; c < r[0].size(); ++c) {
      int lastDir = 0;
      for (size_t k = 1; k < r.size(); ++k) {
        const int dir = (r[k][c] > r[k - 1][c]) - (r[k][c] < r[k - 1][c]);
        if (!dir) continue;
        ++changes;
        reversals += lastDir && dir != lastDir;
        lastDir = dir;
      }
    }
    return std::pair{reversals, changes};
  };
  const auto [reversals, changes] = count(with);
  const auto [reversalsWithout, changesWithout] = count(without);
  size_t coarser = 0;
  for (size_t k = 0; k < with.size(); ++k)
    for (size_t c = 0; c < with[k].size(); ++c) coarser += with[k][c] < without[k][c];
  EXPECT_GT(changes, 0u) << "the dolly should change some chain's rings";
  EXPECT_EQ(reversals, 0u) << reversals << " of " << changes
                           << " ring changes went back against the previous one";
  EXPECT_GT(reversalsWithout, 0u) << "without hysteresis the wobble should flip some chains ("
                                  << changesWithout << " changes)";
  EXPECT_EQ(coarser, 0u) << "frames x chains with fewer rings than eps / 2 needs";
  std::printf("rings: %zu changes, %zu reversals; without hysteresis %zu changes, %zu reversals\n",
              changes, reversals, changesWithout, reversalsWithout);
}

}  // namespace
}  // namespace sylva::mesh
