// cloudgen/grid.h — evaluating the density on a voxel grid over the cloud box.
//
// Units: `voxel` and `origin` are in scene units in the cloud's local frame
// (see model.h); voxel indices are integers, voxel (i,j,k) has its centre at
// origin + (i + 1/2, j + 1/2, k + 1/2) * voxel. The grid is cut into 8^3 tiles
// (the size of an OpenVDB leaf) aligned to index 0.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <vector>

#include "cloudgen/camera.h"
#include "cloudgen/model.h"
#include "cloudgen/parallel.h"

namespace cg {

constexpr int kTile = 8;
constexpr int kTileVoxels = kTile * kTile * kTile;

// Voxels per axis are saturated here (grid_for_voxel): a grid that large is
// refused by the memory estimate before anything is allocated.
inline constexpr int kMaxGridAxis = 1 << 30;

struct GridSpec {
  int n[3];     // voxels per axis
  float voxel;  // edge length, scene units
  vec3 origin;  // corner of voxel (0,0,0), scene units
  std::int64_t voxel_count() const { return std::int64_t(n[0]) * n[1] * n[2]; }
  int tiles(int axis) const { return (n[axis] + kTile - 1) / kTile; }
  vec3 centre(int i, int j, int k) const {
    return {origin[0] + (i + 0.5f) * voxel, origin[1] + (j + 0.5f) * voxel, origin[2] + (k + 0.5f) * voxel};
  }
};

// Cubic voxels, `resolution` of them along the longest box side; the grid is
// centred on the box (it may overhang a shorter side by less than a voxel).
GridSpec grid_for_box(const Model& m, int resolution);
// The same for a given voxel edge (scene units, > 0).
GridSpec grid_for_voxel(const Model& m, float voxel);

inline constexpr int kMaxSupersample = 4;

struct BakeOptions {
  int resolution = 128;
  bool skip_empty = true;  // skip tiles whose shape bound proves them empty
  bool lod = true;         // do not evaluate octaves finer than a voxel can hold
  float tolerance = 0.0f;  // voxels with density <= tolerance are dropped (background 0)
  // Box-filtered bake: each voxel holds the mean of supersample^3 samples on a
  // regular sub-grid of its cell (1 = the centre only). A thin layer of
  // thresholded noise has edges sharper than its voxel; point samples alias
  // them into stripes (docs/gallery/moire), the cell's mean does not. The LOD
  // then keeps octaves down to the sub-sample spacing. Cost: supersample^3.
  // A cell that overhangs the model's box (the grid may, by less than a voxel;
  // a layer thinner than a voxel is one cell through) is sampled only on its
  // part inside the box, the same split there, and weighted by that part's
  // share of the cell: at 1, the density at the part's centre x the share.
  int supersample = 1;
  // supersample clamped to [1, kMaxSupersample]: what the bake, its key and its file use.
  int samples_per_axis() const {
    return supersample < 1 ? 1 : supersample > kMaxSupersample ? kMaxSupersample : supersample;
  }
  int threads = 0;          // 0 = one per hardware thread
  float voxel = 0.0f;       // > 0: this voxel edge instead of `resolution` (camera-aware bake)
  bool use_region = false;  // bake only tiles that meet `region` (camera-aware bake)
  Frustum region{};
  // A brick of a bake split across processes or machines: of the grid's tiles,
  // in index order (x fastest, then y, then z), the brick_index-th of
  // brick_count contiguous, near-equal ranges. Bricks of one grid are disjoint,
  // and their tiles together are the whole bake's, value for value.
  int brick_index = 0;
  int brick_count = 1;
  // A square ring of the horizontal plane (one level of a nested bake of a
  // layer, docs/camera.md): with c = max(|x|, |y|) of a voxel centre in the
  // cloud's frame, only voxels with ring_inner - voxel <= c < ring_outer + voxel
  // hold density (one voxel of margin for trilinear reads at the ring's edges),
  // and tiles whose footprint widened by a voxel lies wholly in the hole or
  // wholly outside are culled. The default (0, +inf) bakes everything.
  float ring_inner = 0.0f;
  float ring_outer = std::numeric_limits<float>::infinity();
  bool has_ring() const { return ring_inner > 0.0f || ring_outer < std::numeric_limits<float>::infinity(); }
};

// Tile index range [first, last) of the options' brick, of `total` tiles.
struct TileSpan {
  std::int64_t first, last;
};
TileSpan brick_tiles(std::int64_t total, const BakeOptions& options);

GridSpec bake_grid(const Model& m, const BakeOptions& options);

struct Tile {
  std::array<int, 3> index;               // voxel index of the tile's first voxel
  std::array<float, kTileVoxels> values;  // x fastest: values[(k*8 + j)*8 + i]
};

struct BakeStats {
  std::int64_t tiles_total = 0, tiles_skipped = 0, tiles_culled = 0, tiles_evaluated = 0, tiles_kept = 0;
  std::int64_t voxels_evaluated = 0, voxels_active = 0;
  std::int64_t samples_evaluated = 0;  // density evaluations: voxels_evaluated * supersample^3
  float lod_worley_octaves = 0, lod_perlin_octaves = 0;
};

struct BakeResult {
  GridSpec grid;
  std::vector<Tile> tiles;  // only tiles with at least one voxel above tolerance
  BakeStats stats;
};

// Worst-case bytes a bake needs (tile storage plus an OpenVDB tree of the
// tiles that the shape bound cannot prove empty); computed without noise, in
// double, saturated at INT64_MAX (never wraps: --resolution 1000000 once gave
// a negative estimate and passed the memory check).
std::int64_t estimate_bake_bytes(const Model& m, const BakeOptions& options);

struct Cancelled : std::exception {
  const char* what() const noexcept override { return "cancelled"; }
};

// Evaluates the density on the grid. Throws Cancelled when progress returns false.
BakeResult bake(const Model& m, const BakeOptions& options, const Progress& progress = {});

// ---- 2D cross-section (the thesis's interactive preview, section 4.4) ----

struct SliceSpec {
  int axis = 0;         // 0 = x, 1 = y, 2 = z: the axis the plane is perpendicular to
  float offset = 0.5f;  // plane position as a generated coordinate in [0, 1] (0.5 = centre)
  int width = 256, height = 256;
  bool lod = false;  // limit octaves to the pixel footprint
  int threads = 0;
};

// Image axes: axis x → columns along +y, rows along z; axis y → columns +x,
// rows z; axis z → columns +x, rows y. Row 0 is the top (largest coordinate).
// The image spans the box face; pixel centres are sampled.
void slice_axes(int axis, int& column_axis, int& row_axis);
vec3 slice_point(const Model& m, const SliceSpec& s, int column, int row);

// Row-major densities, height rows of width values.
std::vector<float> slice(const Model& m, const SliceSpec& s);

// How a slice is shown to the eye (the CLI's PNG, the add-on's live preview):
// grey = 1 − exp(−density / S), with S = slice_display_scale(peak of the slice)
// = max(peak / 3, 0.001): the slice's peak shows at 95 % grey whatever the
// Density slider, so a dense cumulus (peak 48) is not a white block and a thin
// cirrus (peak 0.5) is not black; the edges' ramp stays visible. A peak that is
// not finite, zero or below 0.003 gives 0.001 (such a slice is practically empty).
constexpr float kSliceDisplayMinScale = 0.001f;
float slice_display_scale(float peak);

}  // namespace cg
