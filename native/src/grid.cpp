// grid.cpp — sparse, level-of-detail bake of the density and the 2D slice.
#include "cloudgen/grid.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "cloudgen/density_block.h"

namespace cg {

GridSpec grid_for_box(const Model& m, int resolution) {
  const float longest = std::max({m.box[0], m.box[1], m.box[2]});
  return grid_for_voxel(m, longest / float(std::max(resolution, 1)));
}

GridSpec bake_grid(const Model& m, const BakeOptions& o) {
  return o.voxel > 0.0f ? grid_for_voxel(m, o.voxel) : grid_for_box(m, o.resolution);
}

GridSpec grid_for_voxel(const Model& m, float voxel) {
  GridSpec g{};
  g.voxel = voxel;
  for (int a = 0; a < 3; ++a) {
    // In double and saturated: a tiny voxel must not overflow int (the memory
    // guard then refuses the saturated grid, see estimate_bake_bytes).
    const double n = std::ceil(double(m.box[a]) / double(g.voxel) - 1e-4);
    g.n[a] = n >= double(kMaxGridAxis) || !(n == n) ? kMaxGridAxis : std::max(1, static_cast<int>(n));
    g.origin[a] = -0.5f * float(g.n[a]) * g.voxel;
  }
  return g;
}

namespace {

struct TileRange {
  int lo[3], hi[3];  // voxel index range [lo, hi)
};

TileRange tile_range(const GridSpec& g, std::int64_t t) {
  const int tx = g.tiles(0), ty = g.tiles(1);
  const int c[3] = {int(t % tx), int((t / tx) % ty), int(t / (std::int64_t(tx) * ty))};
  TileRange r{};
  for (int a = 0; a < 3; ++a) {
    r.lo[a] = c[a] * kTile;
    r.hi[a] = std::min(r.lo[a] + kTile, g.n[a]);
  }
  return r;
}

// Upper bound of the unscaled density over the points a tile samples: its
// voxel centres, widened by `reach` (how far a sample may lie from its voxel's centre).
float tile_bound(const Model& m, const GridSpec& g, const TileRange& r, float reach = 0.0f) {
  vec3 lo = g.centre(r.lo[0], r.lo[1], r.lo[2]);
  vec3 hi = g.centre(r.hi[0] - 1, r.hi[1] - 1, r.hi[2] - 1);
  for (int a = 0; a < 3; ++a) lo[a] -= reach, hi[a] += reach;
  return shape_upper_bound(m, lo, hi);
}

// Offset of sub-sample s (of k per axis) from the voxel's centre, in voxels: the
// centres of a k-cell split of [-1/2, 1/2].
float sub_offset(int s, int k) { return (float(s) + 0.5f) / float(k) - 0.5f; }

// The part of a voxel's cell inside the model's box, per axis: clipped where the cell
// overhangs the box, [lo, lo + span] then; share is the part's volume over the cell's.
struct CellPart {
  bool clipped[3];
  float lo[3], span[3];
  float share;
};

CellPart cell_part(const Model& m, float voxel, const vec3& c) {
  CellPart p{};
  p.share = 1.0f;
  for (int a = 0; a < 3; ++a) {
    const float half = 0.5f * m.box[a];
    const float lo = c[a] - 0.5f * voxel, hi = c[a] + 0.5f * voxel;
    p.clipped[a] = lo < -half || hi > half;
    p.lo[a] = std::max(lo, -half);
    p.span[a] = std::max(std::min(hi, half) - p.lo[a], 0.0f);
    if (p.clipped[a]) p.share *= p.span[a] / voxel;
  }
  return p;
}

// How far a voxel's samples may lie from its centre along an axis (scene units): anywhere
// in its cell, since a cell clipped by the box is sampled inside the box (cell_part).
float sample_reach(float voxel) { return 0.5f * voxel; }

std::int64_t tile_count(const GridSpec& g) { return std::int64_t(g.tiles(0)) * g.tiles(1) * g.tiles(2); }

// The box [lo, hi] lies wholly in the ring's hole (max(|x|, |y|) < inner
// everywhere) or wholly outside its outer square (>= outer everywhere).
bool box_outside_ring(const BakeOptions& o, const vec3& lo, const vec3& hi) {
  const float farthest = std::max({-lo[0], hi[0], -lo[1], hi[1]});
  const float nearest = std::max({lo[0], -hi[0], lo[1], -hi[1], 0.0f});
  return farthest < o.ring_inner || nearest >= o.ring_outer;
}

// The voxel centre p is in the ring, widened by one voxel on either side.
bool in_ring(const BakeOptions& o, float voxel, const vec3& p) {
  const float c = std::max(std::fabs(p[0]), std::fabs(p[1]));
  return c >= o.ring_inner - voxel && c < o.ring_outer + voxel;
}

// Outside the camera region or the ring: the tile's voxels, widened by one
// voxel (their trilinear footprint), lie wholly outside a plane of the frustum,
// wholly in the ring's hole or wholly beyond its outer square.
bool tile_culled(const BakeOptions& o, const GridSpec& g, const TileRange& r) {
  if (!o.use_region && !o.has_ring()) return false;
  vec3 lo, hi;
  for (int a = 0; a < 3; ++a) {
    lo[a] = g.origin[a] + float(r.lo[a] - 1) * g.voxel;
    hi[a] = g.origin[a] + float(r.hi[a] + 1) * g.voxel;
  }
  return (o.use_region && box_outside(o.region, lo, hi)) || (o.has_ring() && box_outside_ring(o, lo, hi));
}

}  // namespace

TileSpan brick_tiles(std::int64_t total, const BakeOptions& o) {
  const std::int64_t n = std::max(o.brick_count, 1);
  const std::int64_t i = std::clamp<std::int64_t>(o.brick_index, 0, n - 1);
  // total * i / n without overflow: total < 2^62 / n for any grid that fits in memory
  return {total / n * i + total % n * i / n, total / n * (i + 1) + total % n * (i + 1) / n};
}

std::int64_t estimate_bake_bytes(const Model& m, const BakeOptions& o) {
  const GridSpec g = bake_grid(m, o);
  // Tiles counted in double: 2^27 tiles per axis would overflow int64.
  const double total_tiles = double(g.tiles(0)) * double(g.tiles(1)) * double(g.tiles(2));
  // Counting candidates one by one is cheap (no noise) up to ~10^8 tiles;
  // beyond that the worst case (every tile of the brick) is the estimate.
  double candidates = std::ceil(total_tiles / double(std::max(o.brick_count, 1)));
  if ((o.skip_empty || o.use_region || o.has_ring()) && total_tiles <= double(std::int64_t(1) << 27)) {
    const TileSpan span = brick_tiles(tile_count(g), o);
    candidates = 0;
    for (std::int64_t t = span.first; t < span.last; ++t) {
      const TileRange r = tile_range(g, t);
      if (tile_culled(o, g, r)) continue;
      if (!o.skip_empty || tile_bound(m, g, r, sample_reach(g.voxel)) > 0.0f) ++candidates;
    }
  }
  // 4 bytes per voxel in the tile list, ~5.5 bytes per active voxel in an
  // OpenVDB float tree (measured, docs/platform.md), and the tile index.
  const double per_tile = kTileVoxels * (4.0 + 5.5) + 64.0;
  const double bytes = candidates * per_tile;  // saturated: never a negative or wrapped estimate
  return bytes >= 9.2e18 ? std::numeric_limits<std::int64_t>::max() : static_cast<std::int64_t>(bytes);
}

BakeResult bake(const Model& m, const BakeOptions& o, const Progress& progress) {
  BakeResult result;
  result.grid = bake_grid(m, o);
  const GridSpec& g = result.grid;
  const int k = o.samples_per_axis();
  const Lod lod = o.lod ? lod_for_footprint(m, g.voxel / float(k)) : kNoLod;
  const float reach = sample_reach(g.voxel);
  const bool ring = o.has_ring();
  result.stats.lod_worley_octaves = lod.worley_octaves;
  result.stats.lod_perlin_octaves = lod.perlin_octaves;

  const TileSpan span = brick_tiles(tile_count(g), o);
  const std::int64_t total = span.last - span.first;
  const int threads = resolve_threads(o.threads);
  struct WorkerOut {
    std::vector<Tile> tiles;
    BakeStats stats;
  };
  std::vector<WorkerOut> out(threads);

  auto body = [&](std::int64_t t, int worker) {
    WorkerOut& w = out[worker];
    const TileRange r = tile_range(g, span.first + t);
    if (tile_culled(o, g, r)) {
      ++w.stats.tiles_culled;
      return;
    }
    if (o.skip_empty && tile_bound(m, g, r, reach) <= 0.0f) {
      ++w.stats.tiles_skipped;
      return;
    }
    ++w.stats.tiles_evaluated;
    Tile tile;
    tile.index = {r.lo[0], r.lo[1], r.lo[2]};
    tile.values.fill(0.0f);
    // The tile's voxel centres; with supersampling one batch per sub-sample
    // offset (density_block: lanes across voxels), summed in `values`.
    std::array<vec3, kTileVoxels> centres, points;
    std::array<float, kTileVoxels> values, sample;
    std::size_t count = 0;
    for (int z = r.lo[2]; z < r.hi[2]; ++z)
      for (int y = r.lo[1]; y < r.hi[1]; ++y)
        for (int x = r.lo[0]; x < r.hi[0]; ++x) centres[count++] = g.centre(x, y, z);
    // A voxel that overhangs the box (the density is 0 outside it) is sampled over its
    // part inside the box and weighted by that part's share of the cell: the same mean,
    // but a layer thinner than a voxel keeps its column's density instead of falling
    // between the sub-samples or, point-sampled (K = 1: one sample at the centre of
    // the part), becoming a voxel thick. Cells wholly inside are sampled at their
    // centre (K = 1) or on the K-cell split's centres.
    std::array<CellPart, kTileVoxels> parts;
    for (std::size_t q = 0; q < count; ++q) parts[q] = cell_part(m, g.voxel, centres[q]);
    std::fill(values.begin(), values.begin() + count, 0.0f);
    for (int sz = 0; sz < k; ++sz)
      for (int sy = 0; sy < k; ++sy)
        for (int sx = 0; sx < k; ++sx) {
          const int s[3] = {sx, sy, sz};
          for (std::size_t q = 0; q < count; ++q)
            for (int a = 0; a < 3; ++a)
              points[q][a] = parts[q].clipped[a] ? parts[q].lo[a] + (float(s[a]) + 0.5f) / float(k) * parts[q].span[a]
                                                 : centres[q][a] + sub_offset(s[a], k) * g.voxel;
          density_block(m, points.data(), count, lod, sample.data());
          for (std::size_t q = 0; q < count; ++q) values[q] += sample[q];
        }
    const float inv = 1.0f / float(k * k * k);
    for (std::size_t q = 0; q < count; ++q) {
      values[q] *= inv;
      if (parts[q].share < 1.0f) values[q] *= parts[q].share;
    }
    std::int64_t active = 0;
    std::size_t q = 0;
    for (int z = r.lo[2]; z < r.hi[2]; ++z)
      for (int y = r.lo[1]; y < r.hi[1]; ++y)
        for (int x = r.lo[0]; x < r.hi[0]; ++x) {
          float d = values[q];
          if (d <= o.tolerance || (ring && !in_ring(o, g.voxel, centres[q]))) d = 0.0f;
          ++q;
          active += d > 0.0f;
          tile.values[((z - r.lo[2]) * kTile + (y - r.lo[1])) * kTile + (x - r.lo[0])] = d;
        }
    w.stats.voxels_evaluated += std::int64_t(count);
    w.stats.samples_evaluated += std::int64_t(count) * k * k * k;
    if (active > 0) {
      w.stats.voxels_active += active;
      ++w.stats.tiles_kept;
      w.tiles.push_back(tile);
    }
  };

  if (!parallel_for(total, threads, body, progress)) throw Cancelled();

  result.stats.tiles_total = total;
  for (WorkerOut& w : out) {
    result.stats.tiles_skipped += w.stats.tiles_skipped;
    result.stats.tiles_culled += w.stats.tiles_culled;
    result.stats.tiles_evaluated += w.stats.tiles_evaluated;
    result.stats.tiles_kept += w.stats.tiles_kept;
    result.stats.voxels_evaluated += w.stats.voxels_evaluated;
    result.stats.samples_evaluated += w.stats.samples_evaluated;
    result.stats.voxels_active += w.stats.voxels_active;
    for (Tile& t : w.tiles) result.tiles.push_back(t);
  }
  // Deterministic order, whatever the thread schedule was.
  std::sort(result.tiles.begin(), result.tiles.end(), [](const Tile& a, const Tile& b) { return a.index < b.index; });
  return result;
}

void slice_axes(int axis, int& column_axis, int& row_axis) {
  column_axis = axis == 0 ? 1 : 0;
  row_axis = axis == 2 ? 1 : 2;
}

vec3 slice_point(const Model& m, const SliceSpec& s, int column, int row) {
  int ca, ra;
  slice_axes(s.axis, ca, ra);
  vec3 gcoord;
  gcoord[s.axis] = s.offset;
  gcoord[ca] = (float(column) + 0.5f) / float(s.width);
  gcoord[ra] = 1.0f - (float(row) + 0.5f) / float(s.height);
  return {(gcoord[0] - 0.5f) * m.box[0], (gcoord[1] - 0.5f) * m.box[1], (gcoord[2] - 0.5f) * m.box[2]};
}

float slice_display_scale(float peak) {
  return std::isfinite(peak) ? std::max(kSliceDisplayMinScale, peak / 3.0f) : kSliceDisplayMinScale;
}

std::vector<float> slice(const Model& m, const SliceSpec& s) {
  std::vector<float> image(std::size_t(s.width) * std::size_t(s.height), 0.0f);
  int ca, ra;
  slice_axes(s.axis, ca, ra);
  const float footprint = std::max(m.box[ca] / float(s.width), m.box[ra] / float(s.height));
  const Lod lod = s.lod ? lod_for_footprint(m, footprint) : kNoLod;
  // Small images are not worth a thread start.
  const int threads = std::int64_t(s.width) * s.height < 4096 ? 1 : resolve_threads(s.threads);
  parallel_for(s.height, threads, [&](std::int64_t row, int) {
    std::vector<vec3> points(std::size_t(s.width));  // one row, evaluated in one batch
    for (int c = 0; c < s.width; ++c) points[std::size_t(c)] = slice_point(m, s, c, int(row));
    density_block(m, points.data(), points.size(), lod, &image[std::size_t(row) * s.width]);
  });
  return image;
}

}  // namespace cg
