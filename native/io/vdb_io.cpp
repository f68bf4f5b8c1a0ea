// io/vdb_io.cpp — the only translation unit that includes OpenVDB.
#include "io/vdb_io.h"

#include <openvdb/io/Compression.h>
#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Count.h>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <memory>

#include <mutex>
#include <sstream>

#include "cloudgen/parallel.h"
#include "cloudgen/param_io.h"
#include "io/atomic_file.h"
#include "io/vdb_check.h"

namespace cgio {

static_assert(VdbHeaderLimits{}.max_version == openvdb::OPENVDB_FILE_VERSION,
              "vdb_check.h: the newest file version is this OpenVDB's");

namespace {

void init_openvdb() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

// Builds the tree leaf by leaf from the 8^3 tiles, which are aligned exactly
// like OpenVDB's leaf nodes (origin multiple of 8). Tiles are x-fastest;
// leaves are z-fastest, so the offset is recomputed per voxel. The leaves are
// filled in parallel (`threads` as cg::parallel_for), then linked into the tree
// in one pass; the tree (and the file) do not depend on the order.
openvdb::FloatGrid::Ptr grid_from_bake(const cg::BakeResult& bake, int threads) {
  using Leaf = openvdb::FloatTree::LeafNodeType;
  static_assert(Leaf::DIM == cg::kTile, "tile = leaf");
  auto grid = openvdb::FloatGrid::create(0.0f);
  grid->setName("density");
  grid->setGridClass(openvdb::GRID_FOG_VOLUME);
  const cg::GridSpec& g = bake.grid;
  const double v = g.voxel;
  auto xform = openvdb::math::Transform::createLinearTransform(v);
  xform->postTranslate(
      openvdb::Vec3d(double(g.origin[0]) + 0.5 * v, double(g.origin[1]) + 0.5 * v, double(g.origin[2]) + 0.5 * v));
  grid->setTransform(xform);
  std::vector<std::unique_ptr<Leaf>> leaves(bake.tiles.size());
  cg::parallel_for(std::int64_t(bake.tiles.size()), threads, [&](std::int64_t t, int) {
    const cg::Tile& tile = bake.tiles[std::size_t(t)];
    std::unique_ptr<Leaf> leaf;
    for (int k = 0; k < cg::kTile; ++k)
      for (int j = 0; j < cg::kTile; ++j)
        for (int i = 0; i < cg::kTile; ++i) {
          const float d = tile.values[(k * cg::kTile + j) * cg::kTile + i];
          if (!(d > 0.0f)) continue;  // background: inactive 0 (also drops NaN, which the kernel never makes)
          if (!leaf) leaf = std::make_unique<Leaf>(openvdb::Coord(tile.index[0], tile.index[1], tile.index[2]), 0.0f);
          leaf->setValueOn(openvdb::Index((i << 6) | (j << 3) | k), d);
        }
    leaves[std::size_t(t)] = std::move(leaf);
  });
  auto& tree = grid->tree();
  for (auto& leaf : leaves)
    if (leaf) tree.addLeaf(leaf.release());
  return grid;
}

VdbGridInfo describe(const openvdb::GridBase& grid) {
  VdbGridInfo info;
  info.name = grid.getName();
  info.grid_class = openvdb::GridBase::gridClassToString(grid.getGridClass());
  info.value_type = grid.valueType();
  const openvdb::Vec3d vs = grid.voxelSize();
  info.voxel_size = {vs[0], vs[1], vs[2]};
  info.linear = grid.transform().isLinear();
  info.half = grid.saveFloatAsHalf();
  info.active_voxels = static_cast<std::int64_t>(grid.activeVoxelCount());
  const openvdb::CoordBBox box = grid.evalActiveVoxelBoundingBox();
  info.empty = grid.empty() || info.active_voxels == 0;
  if (!info.empty) {
    info.bbox_min = {box.min().x(), box.min().y(), box.min().z()};
    info.bbox_max = {box.max().x(), box.max().y(), box.max().z()};
  }
  if (const auto* fg = dynamic_cast<const openvdb::FloatGrid*>(&grid)) {
    info.leaf_count = static_cast<std::int64_t>(fg->tree().leafCount());
    info.background = fg->background();
    if (!info.empty) {
      const auto mm = openvdb::tools::minMax(fg->tree());
      info.min = mm.min();
      info.max = mm.max();
    }
  }
  for (auto it = grid.beginMeta(); it != grid.endMeta(); ++it)
    if (it->second) info.metadata[it->first] = it->second->str();
  return info;
}

template <typename F>
auto guarded(const std::string& what, F&& f) -> decltype(f()) {
  try {
    return f();
  } catch (const IoError&) {
    throw;
  } catch (const std::bad_alloc&) {  // in the sandboxed reader: its memory limit
    throw IoError(what + ": OpenVDB ran out of the memory allowed for reading it (corrupt or hostile file?)");
  } catch (const openvdb::Exception& e) {
    throw IoError(what + ": " + e.what());
  } catch (const std::exception& e) {
    throw IoError(what + ": " + e.what());
  }
}

constexpr const char* kBrickMeta = "cloudgen_brick";
constexpr const char* kWholeKeyMeta = "cloudgen_whole_bake_key";

// Written through our own stream: openvdb::io::File does not report failed
// writes (a full disk gave exit 0 and a truncated file), the stream state does.
void write_checked(const std::string& path, const openvdb::GridBase::Ptr& grid) {
  std::ofstream os(path, std::ios::binary | std::ios::trunc);
  if (!os) throw IoError("cannot write '" + path + "': " + std::strerror(errno));
  std::uint32_t compression = openvdb::io::COMPRESS_ACTIVE_MASK;
  if (openvdb::io::Archive::hasBloscCompression()) compression |= openvdb::io::COMPRESS_BLOSC;
  openvdb::io::Stream stream(os);
  stream.setCompression(compression);
  openvdb::GridPtrVec grids{grid};
  stream.write(grids);
  os.flush();
  const std::streamoff written = os.good() ? std::streamoff(os.tellp()) : -1;
  os.close();
  if (written <= 0 || os.fail() || file_size(path) != written)
    throw IoError("cannot write '" + path + "': the write failed (disk full?)");
}

std::string meta_text(const openvdb::GridBase& g, const char* key) {
  const auto m = g[key];
  return m ? m->str() : std::string();
}

}  // namespace

MergeStats merge_vdb_bricks(const std::vector<std::string>& bricks, const std::string& path) {
  init_openvdb();
  if (bricks.empty()) throw IoError("merge: no bricks given");
  openvdb::FloatGrid::Ptr out;
  std::vector<bool> seen;
  std::string whole_key;
  for (const std::string& brick : bricks) {
    const std::string what = "merge: brick '" + brick + "'";
    openvdb::FloatGrid::Ptr grid = guarded(what, [&] {
      openvdb::io::File file(brick);
      file.open(false);
      if (!file.hasGrid("density")) throw IoError(what + " has no grid named 'density'");
      auto g = openvdb::gridPtrCast<openvdb::FloatGrid>(file.readGrid("density"));
      file.close();
      if (!g) throw IoError(what + ": grid 'density' is not a float grid");
      return g;
    });
    const std::string tag = meta_text(*grid, kBrickMeta);
    unsigned long index = 0, count = 0;
    char slash = 0;
    std::istringstream in(tag);
    if (!(in >> index >> slash >> count) || slash != '/' || count == 0 || index >= count || count > 1000000)
      throw IoError(what + " is not a brick of a split bake (no valid " + kBrickMeta + " metadata)");
    if (seen.empty()) {
      seen.assign(count, false);
      whole_key = meta_text(*grid, kWholeKeyMeta);
    }
    if (count != seen.size())
      throw IoError(what + " is brick " + tag + ", the first was of " + std::to_string(seen.size()));
    if (meta_text(*grid, kWholeKeyMeta) != whole_key) throw IoError(what + " belongs to another bake (whole bake key)");
    if (seen[index]) throw IoError(what + ": brick " + tag + " is given twice");
    seen[index] = true;
    if (!out) {
      out = grid;
      continue;
    }
    if (grid->transform() != out->transform()) throw IoError(what + " has another voxel grid (transform)");
    out->tree().merge(grid->tree());  // disjoint leaves: every brick's voxels are moved over
  }
  for (std::size_t i = 0; i < seen.size(); ++i)
    if (!seen[i])
      throw IoError("merge: brick " + std::to_string(i) + "/" + std::to_string(seen.size()) + " is missing");
  out->removeMeta(kBrickMeta);
  out->removeMeta(kWholeKeyMeta);
  out->removeMeta("cloudgen_bake_key");
  if (!whole_key.empty()) out->insertMeta("cloudgen_bake_key", openvdb::StringMetadata(whole_key));
  guarded("cannot write '" + path + "'", [&] { write_checked(path, out); });
  return {int(seen.size()), static_cast<std::int64_t>(out->activeVoxelCount())};
}

void write_vdb(const std::string& path, const cg::BakeResult& bake, const VdbWriteOptions& o) {
  init_openvdb();
  guarded("cannot write '" + path + "'", [&] {
    auto grid = grid_from_bake(bake, o.threads);
    grid->insertMeta("cloudgen_version", openvdb::StringMetadata(cg::version()));
    grid->insertMeta("cloudgen_params", openvdb::StringMetadata(o.params_json));
    if (!o.preset.empty()) grid->insertMeta("cloudgen_preset", openvdb::StringMetadata(o.preset));
    grid->insertMeta("cloudgen_time", openvdb::FloatMetadata(o.time));
    grid->insertMeta("cloudgen_resolution", openvdb::Int32Metadata(o.resolution));
    if (!o.bake_key.empty()) grid->insertMeta("cloudgen_bake_key", openvdb::StringMetadata(o.bake_key));
    if (!o.brick.empty()) {
      grid->insertMeta(kBrickMeta, openvdb::StringMetadata(o.brick));
      grid->insertMeta(kWholeKeyMeta, openvdb::StringMetadata(o.whole_bake_key));
    }
    grid->insertMeta("cloudgen_lod_worley_octaves", openvdb::FloatMetadata(bake.stats.lod_worley_octaves));
    grid->insertMeta("cloudgen_lod_perlin_octaves", openvdb::FloatMetadata(bake.stats.lod_perlin_octaves));
    if (o.supersample > 1) grid->insertMeta("cloudgen_supersample", openvdb::Int32Metadata(o.supersample));
    grid->setSaveFloatAsHalf(o.half);

    write_checked(path, grid);
  });
}

VdbFileInfo read_vdb_info(const std::string& path) {
  init_openvdb();
  return guarded("cannot read '" + path + "'", [&] {
    openvdb::io::File file(path);
    file.open(false);  // no delayed loading: we read it all now, while the file is ours
    VdbFileInfo out;
    out.version = file.version();
    out.compression = openvdb::io::compressionToString(file.compression());
    auto grids = file.getGrids();
    file.close();
    if (grids)
      for (const auto& g : *grids)
        if (g) out.grids.push_back(describe(*g));
    return out;
  });
}

struct VdbFloatGrid::Impl {
  openvdb::FloatGrid::Ptr grid;
};

VdbFloatGrid::VdbFloatGrid(const std::string& path, const std::string& name) : impl_(new Impl) {
  init_openvdb();
  guarded("cannot read '" + path + "'", [&] {
    openvdb::io::File file(path);
    file.open(false);
    if (!file.hasGrid(name)) throw IoError("'" + path + "' has no grid named '" + name + "'");
    auto base = file.readGrid(name);
    file.close();
    impl_->grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
    if (!impl_->grid) throw IoError("'" + path + "': grid '" + name + "' is not a float grid");
    info_ = describe(*impl_->grid);
  });
}

VdbFloatGrid::~VdbFloatGrid() = default;
VdbFloatGrid::VdbFloatGrid(VdbFloatGrid&&) noexcept = default;

float VdbFloatGrid::value(int i, int j, int k) const { return impl_->grid->tree().getValue(openvdb::Coord(i, j, k)); }

bool VdbFloatGrid::active(int i, int j, int k) const { return impl_->grid->tree().isValueOn(openvdb::Coord(i, j, k)); }

std::array<double, 3> VdbFloatGrid::index_to_world(double i, double j, double k) const {
  const openvdb::Vec3d w = impl_->grid->transform().indexToWorld(openvdb::Vec3d(i, j, k));
  return {w[0], w[1], w[2]};
}

std::vector<VdbFloatGrid::Voxel> VdbFloatGrid::active_voxels() const {
  std::vector<Voxel> out;
  for (auto it = impl_->grid->cbeginValueOn(); it; ++it) {
    if (!it.isVoxelValue()) {  // an active tile: report each voxel it covers
      openvdb::CoordBBox b;
      it.getBoundingBox(b);
      for (auto c = b.begin(); c; ++c) out.push_back({{(*c).x(), (*c).y(), (*c).z()}, *it});
      continue;
    }
    const openvdb::Coord c = it.getCoord();
    out.push_back({{c.x(), c.y(), c.z()}, *it});
  }
  return out;
}

std::vector<VdbFloatGrid::Voxel> VdbFloatGrid::all_leaf_values() const {
  std::vector<Voxel> out;
  for (auto leaf = impl_->grid->tree().cbeginLeaf(); leaf; ++leaf)
    for (auto it = leaf->cbeginValueAll(); it; ++it) {
      const openvdb::Coord c = it.getCoord();
      out.push_back({{c.x(), c.y(), c.z()}, *it});
    }
  return out;
}

}  // namespace cgio
