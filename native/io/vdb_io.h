// io/vdb_io.h — writing a bake as an OpenVDB file, and reading it back.
//
// The file holds one openvdb::FloatGrid named "density", grid class fog
// volume, background 0; only voxels with density > 0 are active. Transform:
// linear, voxel size = grid.voxel, index (i,j,k) → local (i,j,k)·voxel +
// origin + voxel/2, i.e. the voxel centre of cg::GridSpec::centre(), in the
// cloud object's local frame. Metadata on the grid: cloudgen_version,
// cloudgen_params (JSON), cloudgen_preset (if any), cloudgen_time,
// cloudgen_resolution, cloudgen_lod_worley_octaves, cloudgen_lod_perlin_octaves,
// cloudgen_bake_key (when given), cloudgen_supersample (a box-filtered bake only).
// Blosc compression (when the library has it); optionally 16-bit floats.
//
// OpenVDB itself stays inside vdb_io.cpp: the reader hands out plain values.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "cloudgen/grid.h"

namespace cgio {

struct VdbWriteOptions {
  bool half = false;        // saveFloatAsHalf
  std::string params_json;  // cg::params_to_json of the baked parameters
  std::string preset;       // empty: no cloudgen_preset entry
  float time = 0.0f;        // the `time` parameter baked
  int resolution = 0;
  std::string bake_key;  // field key + bake settings (`bake --update` compares it)
  // A brick of a split bake (BakeOptions::brick_*): "I/N" and the key the whole
  // bake has; `cloudgen merge` checks and drops both. Empty: a whole bake.
  std::string brick;
  std::string whole_bake_key;
  int threads = 0;      // building the tree: as cg::BakeOptions::threads (0 = one per core)
  int supersample = 1;  // > 1: written as cloudgen_supersample (cg::BakeOptions::supersample)
};

// Writes `bake` to `path` (the caller passes a temporary, see atomic_file.h).
// Throws IoError. Calls openvdb::initialize() once.
void write_vdb(const std::string& path, const cg::BakeResult& bake, const VdbWriteOptions& options);

// Merges the bricks of one split bake (every "I/N" of one N, one whole-bake key,
// one transform) into `path` (a temporary, see atomic_file.h): one `density`
// grid with the whole bake's key and the bricks' other metadata. Reads one
// brick at a time into the sparse result: memory is the result plus one brick.
// Throws IoError naming the brick that is missing, repeated or does not fit.
struct MergeStats {
  int bricks = 0;
  std::int64_t active_voxels = 0;
};
MergeStats merge_vdb_bricks(const std::vector<std::string>& bricks, const std::string& path);

// One grid of a file as read back by OpenVDB.
struct VdbGridInfo {
  std::string name, grid_class, value_type;
  std::array<double, 3> voxel_size{};
  bool linear = false;  // the transform is a linear map
  bool half = false;    // stored as 16-bit floats
  std::int64_t active_voxels = 0, leaf_count = 0;
  double min = 0, max = 0;  // over the active voxels (0, 0 when empty)
  bool empty = true;
  std::array<int, 3> bbox_min{}, bbox_max{};  // active index bounding box (inclusive)
  double background = 0;
  std::map<std::string, std::string> metadata;  // user metadata as text
};

struct VdbFileInfo {
  std::string version;  // file format / library version as text
  std::string compression;
  std::vector<VdbGridInfo> grids;
};

// Reads the grids' headers, statistics and metadata. Throws IoError for a
// missing, unreadable or malformed file (all OpenVDB exceptions are caught).
VdbFileInfo read_vdb_info(const std::string& path);

// A float grid read back for comparisons (tests): values by voxel index.
class VdbFloatGrid {
 public:
  // Throws IoError unless `path` holds a float grid named `name`.
  VdbFloatGrid(const std::string& path, const std::string& name = "density");
  ~VdbFloatGrid();
  VdbFloatGrid(VdbFloatGrid&&) noexcept;

  const VdbGridInfo& info() const { return info_; }
  float value(int i, int j, int k) const;  // the background where inactive
  bool active(int i, int j, int k) const;
  // Index → local (world) position through the grid's transform.
  std::array<double, 3> index_to_world(double i, double j, double k) const;
  struct Voxel {
    std::array<int, 3> ijk;
    float value;
  };
  std::vector<Voxel> active_voxels() const;
  // Every stored value, active or not, inside the leaf nodes (for checking
  // that inactive voxels hold 0 and nothing is NaN/Inf).
  std::vector<Voxel> all_leaf_values() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  VdbGridInfo info_;
};

}  // namespace cgio
