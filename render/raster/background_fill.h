#pragma once
// Writes the output pixels of tiles that no triangle touches (pure background)
// in long row runs rather than tile by tile.
//
// A background pixel costs 20 bytes of non-temporal writes (float RGBA +
// depth) and no arithmetic. Written tile by tile, every tile row is a 1 KiB
// colour chunk plus a 256-byte depth chunk at another address, and such short
// streaming chunks run at about half the speed of long ones (a stand-alone
// loop on the loaded 2-core EPYC VM filling a 1920x1080 frame: 3.5-3.8 ms in
// 64x64 tiles, 1.5-2.1 ms row by row).
// So a unit here is one output row of a run of horizontally adjacent
// background tiles: the top and bottom bands of a frame become whole image
// rows.
//
//   BackgroundFill fill;
//   std::atomic<std::size_t> cursor{0};
//   fill.Plan(raster, ss, sample_rows, transparent, image.width, image.height, cursor);
//   // on the frame's threads, a share after each shaded tile (the stores
//   // then drain while the next tile computes), and after their other work:
//   fill.Drain(share, image);
//   fill.Drain(fill.units(), image);
//
// Every unit is claimed exactly once through the shared cursor and writes
// values that depend only on its position, so the image bytes do not depend
// on the thread count or on which thread wrote what.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "render/image.h"
#include "render/raster/rasterizer.h"

namespace render {

class BackgroundFill {
 public:
  // One unit: output pixels [x0, x1) of output row y.
  struct Unit {
    int y = 0;
    int x0 = 0, x1 = 0;
  };

  // Plans one frame: units for the tiles of `raster` with no binned triangle,
  // top to bottom, left to right. `sample_rows` holds the background colour
  // of each sample row of the raster (raster.height() entries); `supersample`
  // (1, 2 or 4) samples per axis per output pixel of a width x height image
  // (raster size = image size * supersample). A pixel's colour is the mean of
  // its samples' rows summed in sample order (the shading path's order),
  // alpha 1; transparent: all zero. `cursor` is shared by every thread of the
  // frame and must outlive it; Plan resets it to 0.
  void Plan(const Rasterizer& raster, int supersample, std::span<const glm::vec3> sample_rows,
            bool transparent, int width, int height, std::atomic<std::size_t>& cursor);

  // Number of units of the planned frame, and unit `u` (< units()).
  std::size_t units() const { return units_.size(); }
  const Unit& unit(std::size_t u) const { return units_[u]; }

  // Writes unit `u` into `image`: rgba, and depth (+inf) when image.depth is
  // not empty.
  void WriteUnit(std::size_t u, Image& image) const;

  // Claims up to `n` units from the cursor and writes them; returns how many
  // were written (fewer once every unit is claimed).
  std::size_t Drain(std::size_t n, Image& image) const;

  // The colour every background pixel of output row `y` gets.
  const glm::vec4& row_color(int y) const { return row_colors_[static_cast<std::size_t>(y)]; }

 private:
  std::vector<Unit> units_;
  std::vector<glm::vec4> row_colors_;   // per output row
  std::atomic<std::size_t>* cursor_ = nullptr;
};

}  // namespace render
