// libFuzzer target: any bytes as one of cpfg's side files that a view file
// names, chosen by the first byte: a generalized-cylinder contour (.con,
// then sampled), a curve for curveX/curveGAL (then evaluated), or a
// background scene. Must never crash, hang or leak; what a reader accepts
// must evaluate to finite numbers.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "app/cpfg_background.h"
#include "lsys/cpfg_curve.h"
#include "mesh/contour.h"

namespace {

bool Finite(const sylva::Vec3& p) {
  return std::isfinite(p.x()) && std::isfinite(p.y()) && std::isfinite(p.z());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const std::string text(reinterpret_cast<const char*>(data) + 1, size - 1);
  switch (data[0] % 3) {
    case 0: {
      sylva::DiagnosticList warnings;
      auto c = sylva::mesh::ParseContour(text, "fuzz.con", &warnings);
      if (!c) return 0;
      for (int sides : {3, 8}) {
        for (const sylva::Vec3& p : sylva::mesh::SampleContour(*c, sides)) {
          if (!Finite(p)) std::abort();
        }
      }
      return 0;
    }
    case 1: {
      auto c = sylva::lsys::CpfgCurve::Parse(text, "fuzz.crv", 64);
      if (!c) return 0;
      if (!std::isfinite(c->Length())) std::abort();
      for (double t : {0.0, 0.3, 1.0}) {
        if (!Finite(c->AtLength(t)) || !Finite(c->AtParameter(t))) std::abort();
      }
      return 0;
    }
    default: {
      sylva::DiagnosticList warnings;
      auto s = sylva::app::ParseBackgroundScene(text, "fuzz.dat", warnings);
      if (!s) return 0;
      for (const auto& p : s->polygons) {
        for (const sylva::Vec3& v : p.vertices) {
          if (!Finite(v)) std::abort();
        }
      }
      return 0;
    }
  }
}
