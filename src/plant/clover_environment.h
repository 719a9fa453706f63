// cpfg's `clover` environment program, built in: light on a 2D grid over
// the ground, shaded by the leaves the plant itself adds (Mech &
// Prusinkiewicz, "Visual models of plants interacting with their
// environment", SIGGRAPH 1996, section 6: clover). cpfg runs it as a
// separate process; Sylva answers the same ?E modules with the same rules.
//
// The grid (`grid size: NX NY` cells over `grid range: W H` from `grid
// position: X Y`) holds per cell the incoming light (the green channel of
// `input image:`, 0..255; 255 with no image), a ratio (its red channel) and
// a count of leaves above it. After each step the ?E modules are read in
// word order:
//   ?E(x)  or ?E(0, ...)   a query: after all modules are read it gets the
//                          light light/255 * transmittance^leaves of its
//                          cell (0 outside the grid), and with 2 or more
//                          parameters its second becomes ratio/128;
//   ?E(1, a)               adds a leaf: a disc of area a (cells inside
//                          the ellipse of radius sqrt(a/pi) in cells + 1)
//                          counts one more leaf; not answered;
//   ?E(t, a), t not 0 or 1 removes one (counts never leave 0..255).
// Leaves stay in the grid from step to step until removed, unless `remove
// old leaves: on`. Positions are x and y (`z is up`, the default) or x and
// z (`z is up: no`). Coordinates and cells are single-precision floats and
// whole cells, as in the program.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/status.h"
#include "plant/environment.h"

namespace sylva::plant {

struct CloverDef {
  int size[2] = {512, 512};      // `grid size:` cells
  float pos[2] = {-1, -1};       // `grid position:` lower left corner
  float range[2] = {2, 2};       // `grid range:` extent
  float transmittance = 0.6f;    // `transmittance:` of one leaf
  bool removeOldLeaves = false;  // `remove old leaves: on`
  bool zIsUp = true;             // `z is up:`
};

// An input image's channels, rows from the bottom (as SGI images and
// cpfg's programs store them), 0..255.
struct CloverImage {
  int width = 0, height = 0;
  std::vector<uint8_t> red, green;  // width * height each
};

// Reads an SGI image (.rgb, .bw: 8 bits per channel, verbatim or RLE; the
// format of vlab's clover objects); an error names what is wrong. clover's
// other formats (.tga, .png) are not read.
Expected<CloverImage> ReadCloverImage(const std::string& bytes, const std::string& path);

class CloverEnvironment final : public Environment {
 public:
  // `image` null: full light (255) everywhere. `coordinates`: how many the
  // .e file's `turtle position:` sends (2 needed with z up, else 3).
  CloverEnvironment(const CloverDef& def, const CloverImage* image, int coordinates);
  Status Answer(std::span<EnvQuery> queries) override;

  // The leaves above cell (x, y); for tests.
  int Leaves(int x, int y) const { return objects_[size_t(y) * size_t(def_.size[0]) + size_t(x)]; }

 private:
  // The cell of a position, or -1 outside the grid.
  int64_t CellOf(float x, float y) const;
  CloverDef def_;
  int coordinates_;
  std::vector<uint8_t> light_, ratio_, objects_;
  float powers_[256];  // transmittance^k
};

}  // namespace sylva::plant
