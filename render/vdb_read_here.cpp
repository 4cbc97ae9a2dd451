#include "render/vdb_read_here.h"

#include <cmath>
#include <cstring>
#include <optional>
#include <stdexcept>
#include <vector>

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>

#include "render/allocation_limit.h"
#include "render/vdb_volume.h"
#include "render/velocity_answer.h"

namespace morphoflow {

namespace {

// No buffer of a valid volume's reading is near this: a leaf holds 512 voxels.
constexpr size_t kMaxReaderAllocation = size_t(64) << 20;
constexpr const char* kClaimsTooMuch =
    "the file is damaged: a length stored in it asks for more than 64 MiB at once (a valid volume never does)";

bool readVelocityHere(const std::string& path, VelocityVolume* out, std::string* error) {
  try {
    std::optional<AllocationLimit> limit(std::in_place, kMaxReaderAllocation);  // (while OpenVDB reads)
    openvdb::io::File file(path);
    file.open(/*delayLoad=*/false);
    const bool mac = file.hasGrid("vel_mac");
    if (!mac && !file.hasGrid("vel")) {
      std::string names;
      for (auto it = file.beginName(); it != file.endName(); ++it) names += (names.empty() ? "" : ", ") + it.gridName();
      *error = "the file has no velocity grid 'vel' (its grids: " + (names.empty() ? std::string("none") : names) + ")";
      return false;
    }
    openvdb::MetaMap::Ptr meta = file.getMetadata();
    openvdb::GridBase::Ptr base = file.readGrid(mac ? "vel_mac" : "vel");
    file.close();
    limit.reset();
    auto grid = openvdb::gridPtrCast<openvdb::Vec3SGrid>(base);
    if (!grid) {
      *error = "the grid '" + base->getName() + "' is not a Vec3 float grid (it is " + base->valueType() + ")";
      return false;
    }
    const openvdb::math::Transform& t = grid->transform();
    const openvdb::Vec3d vs = t.voxelSize();
    if (!t.isLinear() || std::abs(vs[0] - vs[1]) > 1e-9 * vs[0] || std::abs(vs[0] - vs[2]) > 1e-9 * vs[0]) {
      *error = "the grid '" + grid->getName() + "' does not have cubic voxels on a linear transform";
      return false;
    }
    const openvdb::Vec3d o = t.indexToWorld(openvdb::Vec3d(0.0));
    if (!(std::isfinite(vs[0]) && vs[0] > 0.0 && vs[0] < 1e30) || !std::isfinite(o[0]) || !std::isfinite(o[1]) ||
        !std::isfinite(o[2])) {
      *error = "the grid '" + grid->getName() + "' has a transform that is not finite (voxel size " +
               std::to_string(vs[0]) + ")";
      return false;
    }
    VelocityVolume v;
    v.grid = grid->getName();
    v.staggered = mac || grid->getGridClass() == openvdb::GRID_STAGGERED;
    v.voxelSize = vs[0];
    v.indexOrigin = {o[0], o[1], o[2]};
    if (auto m = meta->getMetadata<openvdb::DoubleMetadata>("time")) v.hasTime = true, v.time = m->value();
    if (auto m = meta->getMetadata<openvdb::Vec3DMetadata>("domain_size"))
      v.hasDomain = true, v.domain = {m->value()[0], m->value()[1], m->value()[2]};
    const openvdb::CoordBBox box = grid->evalActiveVoxelBoundingBox();
    if (!box.empty()) {
      const openvdb::Coord d = box.dim();
      for (int a = 0; a < 3; ++a) v.origin[size_t(a)] = box.min()[a], v.cells[size_t(a)] = d[a];
      const double cells = double(d[0]) * double(d[1]) * double(d[2]);
      // The box of the active voxels is read densely: bounded before anything is allocated.
      if (cells > double(kMaxVelocityCells)) {
        *error = "the velocity's active voxels span " + std::to_string(d[0]) + " x " + std::to_string(d[1]) + " x " +
                 std::to_string(d[2]) + " cells (" + std::to_string(grid->activeVoxelCount()) +
                 " of them active), more than the " + std::to_string(kMaxVelocityCells >> 20) +
                 " Mi cells a velocity volume may span";
        return false;
      }
      const size_t n = size_t(cells);
      std::vector<openvdb::Vec3s> dense(n);
      openvdb::tools::Dense<openvdb::Vec3s, openvdb::tools::LayoutXYZ> dst(box, dense.data());
      openvdb::tools::copyToDense(*grid, dst, /*serial=*/true);
      for (int a = 0; a < 3; ++a) {
        v.values[size_t(a)].resize(n);
        for (size_t i = 0; i < n; ++i) v.values[size_t(a)][i] = dense[i][a];
      }
    }
    *out = std::move(v);
    return true;
  } catch (const std::bad_alloc&) {
    *error = kClaimsTooMuch;
    return false;
  } catch (const std::exception& e) {
    *error = e.what();
    return false;
  }
}

// The `time` metadata, without reading the grids.
std::string timeAnswer(const std::string& path) {
  try {
    AllocationLimit limit(kMaxReaderAllocation);
    openvdb::io::File file(path);
    file.open(/*delayLoad=*/true);
    openvdb::MetaMap::Ptr meta = file.getMetadata();
    file.close();
    auto m = meta->getMetadata<openvdb::DoubleMetadata>("time");
    if (!m) return "0";
    const double t = m->value();
    return "1" + std::string(reinterpret_cast<const char*>(&t), sizeof t);
  } catch (const std::bad_alloc&) {
    return std::string("E") + kClaimsTooMuch;
  } catch (const std::exception& e) {
    return std::string("E") + e.what();
  }
}

std::string summaryAnswer(const std::string& path) {
  try {
    AllocationLimit limit(size_t(4) << 30);
    openvdb::io::File file(path);
    file.open();
    std::string names, values;
    openvdb::GridPtrVecPtr grids = file.getGrids();
    openvdb::MetaMap::Ptr meta = file.getMetadata();
    file.close();
    openvdb::Vec3d domain(0.0);
    if (auto m = meta->getMetadata<openvdb::Vec3DMetadata>("domain_size")) domain = m->value();
    values.append(reinterpret_cast<const char*>(&domain[0]), 3 * sizeof(double));
    for (const openvdb::GridBase::Ptr& g : *grids) {
      names += g->getName() + "\n";
      auto f = openvdb::gridPtrCast<openvdb::FloatGrid>(g);
      if (g->getName() != "density" || !f) continue;
      for (auto v = f->cbeginValueOn(); v; ++v) {
        const float x = *v;
        for (openvdb::Index64 k = 0; k < v.getVoxelCount(); ++k) values.append(reinterpret_cast<const char*>(&x), 4);
      }
    }
    return "N" + names + std::string(1, '\0') + values;
  } catch (const std::bad_alloc&) {
    return std::string("E") + kClaimsTooMuch;
  } catch (const std::exception& e) {
    return std::string("E") + e.what();
  }
}

}  // namespace

std::string vdbReaderAnswer(const std::string& mode, const std::string& path) {
  static const bool initialised = (openvdb::initialize(), true);
  (void)initialised;
  if (mode == "time") return timeAnswer(path);
  if (mode == "summary") return summaryAnswer(path);
  if (mode != "velocity") throw std::invalid_argument("unknown mode '" + mode + "'");
  VelocityVolume v;
  std::string err;
  const bool ok = readVelocityHere(path, &v, &err);
  return encodeVelocityAnswer(ok, v, err);
}

}  // namespace morphoflow
