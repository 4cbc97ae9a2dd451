#include "render/vdb_volume.h"

#include <cmath>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <optional>
#include <sstream>
#include <stdexcept>

#include <openvdb/io/Archive.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>
#include <openvdb/tools/Prune.h>
#include <openvdb/tree/LeafManager.h>
#include <openvdb/tools/TopologyToLevelSet.h>
#include <nanovdb/util/IO.h>
#include <nanovdb/util/OpenToNanoVDB.h>
#include <xxhash.h>

#include "render/allocation_limit.h"
#include "render/isolated_read.h"

namespace morphoflow {

namespace {

void initialiseOnce() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

// Index (0,0,0) at the first cell's centre: world = (index + 1/2) h.
openvdb::math::Transform::Ptr cellTransform(double h) {
  auto t = openvdb::math::Transform::createLinearTransform(h);
  t->postTranslate(openvdb::Vec3d(0.5 * h));
  return t;
}

openvdb::CoordBBox cellBox(const VolumeGrid& g) {
  return openvdb::CoordBBox(openvdb::Coord(0, 0, 0), openvdb::Coord(g.cells[0] - 1, g.cells[1] - 1, g.cells[2] - 1));
}

// Voxels within `tolerance` of the background made inactive (and set to
// it); the rest keep their values exactly. copyFromDense's own tolerance
// would also merge nearly equal voxels into one tile, so it copies exactly.
template <class GridT>
void deactivateNearBackground(GridT* grid, float tolerance) {
  if (tolerance <= 0.0f) return;
  using ValueT = typename GridT::ValueType;
  const ValueT bg = grid->background();
  openvdb::tree::LeafManager<typename GridT::TreeType> leaves(grid->tree());
  leaves.foreach([&](typename GridT::TreeType::LeafNodeType& leaf, size_t) {
    for (auto it = leaf.beginValueOn(); it; ++it)
      if (openvdb::math::isApproxEqual(*it, bg, ValueT(tolerance))) leaf.setValueOff(it.pos(), bg);
  });
  openvdb::tools::pruneInactive(grid->tree());
}

// The options' shared topology for grid g's cells, or null.
const std::vector<uint8_t>* sharedTopology(const VolumeGrid& g, const VolumeOptions& o) {
  for (const VolumeOptions::ActiveMask& m : o.active)
    if (m.cells == g.cells && m.on.size() == g.values[0].size()) return &m.on;
  return nullptr;
}

// The grid filled densely from `values`, or (shared topology) active exactly
// where the options' mask is, whatever the values there.
template <class GridT>
void fill(GridT* grid, const VolumeGrid& g, typename GridT::ValueType* values, const VolumeOptions& o) {
  using ValueT = typename GridT::ValueType;
  const std::vector<uint8_t>* shared = sharedTopology(g, o);
  if (!shared) {
    openvdb::tools::Dense<ValueT, openvdb::tools::LayoutXYZ> dense(cellBox(g), values);
    openvdb::tools::copyFromDense(dense, *grid, ValueT(0.0f));
    deactivateNearBackground(grid, o.tolerance);
    return;
  }
  auto acc = grid->getAccessor();
  const std::vector<uint8_t>& on = *shared;
  size_t i = 0;
  for (int z = 0; z < g.cells[2]; ++z)
    for (int y = 0; y < g.cells[1]; ++y)
      for (int x = 0; x < g.cells[0]; ++x, ++i)
        if (on[i]) acc.setValue(openvdb::Coord(x, y, z), values[i]);
}

openvdb::GridBase::Ptr scalarGrid(const VolumeGrid& g, const VolumeOptions& o) {
  auto grid = openvdb::FloatGrid::create(0.0f);
  fill(grid.get(), g, const_cast<float*>(g.values[0].data()), o);
  if (g.kind == VolumeGrid::Kind::FogVolume) grid->setGridClass(openvdb::GRID_FOG_VOLUME);
  return grid;
}

openvdb::GridBase::Ptr vectorGrid(const VolumeGrid& g, const VolumeOptions& o) {
  std::vector<openvdb::Vec3s> v(g.values[0].size());
  for (size_t i = 0; i < v.size(); ++i) v[i] = openvdb::Vec3s(g.values[0][i], g.values[1][i], g.values[2][i]);
  auto grid = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
  fill(grid.get(), g, v.data(), o);
  grid->setVectorType(g.kind == VolumeGrid::Kind::Color ? openvdb::VEC_INVARIANT : openvdb::VEC_CONTRAVARIANT_RELATIVE);
  if (g.kind == VolumeGrid::Kind::Staggered) grid->setGridClass(openvdb::GRID_STAGGERED);
  return grid;
}

// The solid cells' outline as a narrow-band signed distance (negative inside).
openvdb::GridBase::Ptr levelSetGrid(const VolumeGrid& g) {
  auto mask = openvdb::MaskGrid::create();
  mask->setTransform(cellTransform(g.voxelSize));
  auto acc = mask->getAccessor();
  const std::vector<float>& v = g.values[0];
  for (int z = 0; z < g.cells[2]; ++z)
    for (int y = 0; y < g.cells[1]; ++y)
      for (int x = 0; x < g.cells[0]; ++x)
        if (v[(size_t(z) * size_t(g.cells[1]) + size_t(y)) * size_t(g.cells[0]) + size_t(x)] != 0.0f)
          acc.setValueOn(openvdb::Coord(x, y, z));
  auto ls = openvdb::tools::topologyToLevelSet(*mask, /*halfWidth=*/3, /*closingSteps=*/0);
  ls->setGridClass(openvdb::GRID_LEVEL_SET);
  return ls;
}

openvdb::GridPtrVec buildGrids(const std::vector<VolumeGrid>& grids, const VolumeOptions& o) {
  initialiseOnce();
  openvdb::GridPtrVec out;
  for (const VolumeGrid& g : grids) {
    const bool vector = g.kind == VolumeGrid::Kind::Vector || g.kind == VolumeGrid::Kind::Staggered ||
                        g.kind == VolumeGrid::Kind::Color;
    openvdb::GridBase::Ptr grid = vector                                 ? vectorGrid(g, o)
                                  : g.kind == VolumeGrid::Kind::LevelSet ? levelSetGrid(g)
                                                                         : scalarGrid(g, o);
    grid->setName(g.name);
    grid->setTransform(cellTransform(g.voxelSize));
    grid->setSaveFloatAsHalf(o.half);
    out.push_back(grid);
  }
  return out;
}

openvdb::MetaMap metaMap(const VolumeMetadata& m) {
  openvdb::MetaMap meta;
  meta.insertMeta("frame", openvdb::Int64Metadata(m.frame));
  meta.insertMeta("step", openvdb::Int64Metadata(m.step));
  meta.insertMeta("time", openvdb::DoubleMetadata(m.time));
  meta.insertMeta("dt", openvdb::DoubleMetadata(m.dt));
  meta.insertMeta("scene", openvdb::StringMetadata(m.scene));
  meta.insertMeta("morphoflow_version", openvdb::StringMetadata(m.version));
  meta.insertMeta("settings_hash", openvdb::StringMetadata(m.settingsHash));
  meta.insertMeta("units", openvdb::StringMetadata(m.units));
  if (m.domain[0] > 0)
    meta.insertMeta("domain_size", openvdb::Vec3DMetadata(openvdb::Vec3d(m.domain[0], m.domain[1], m.domain[2])));
  return meta;
}

// Writes to a seekable stream (the in-memory string), as io::File does, so
// that every reader of .vdb files can open the result.
class MemoryArchive : public openvdb::io::Archive {
 public:
  std::string encode(const openvdb::GridPtrVec& grids, const openvdb::MetaMap& meta) const {
    std::ostringstream os(std::ios_base::out | std::ios_base::binary);
    openvdb::GridCPtrVec cgrids(grids.begin(), grids.end());
    Archive::write(os, cgrids, /*seekable=*/true, meta);
    return os.str();
  }
  openvdb::io::Archive::Ptr copy() const override { return std::make_shared<MemoryArchive>(*this); }
};

// The header's UUID (36 characters after the magic number, three version
// numbers and the offsets flag) replaced by one made from the content.
void deterministicUuid(std::string* bytes) {
  constexpr size_t at = 8 + 4 + 4 + 4 + 1, n = 36;
  if (bytes->size() < at + n || (*bytes)[at + 8] != '-') throw std::runtime_error("unexpected VDB header layout");
  const uint64_t a = XXH64(bytes->data() + at + n, bytes->size() - at - n, 1);
  const uint64_t b = XXH64(bytes->data() + at + n, bytes->size() - at - n, 2);
  char uuid[40];
  std::snprintf(uuid, sizeof uuid, "%08x-%04x-4%03x-%04x-%012llx", unsigned(a >> 32), unsigned(a >> 16) & 0xffffu,
                unsigned(a) & 0xfffu, unsigned(0x8000u | (unsigned(b >> 48) & 0x3fffu)),
                static_cast<unsigned long long>(b & 0xffffffffffffULL));
  std::memcpy(bytes->data() + at, uuid, n);
}

}  // namespace

std::string encodeVdb(const std::vector<VolumeGrid>& grids, const VolumeMetadata& meta, const VolumeOptions& o) {
  MemoryArchive archive;
  archive.setCompression(openvdb::io::COMPRESS_BLOSC | openvdb::io::COMPRESS_ACTIVE_MASK);
  std::string bytes = archive.encode(buildGrids(grids, o), metaMap(meta));
  deterministicUuid(&bytes);
  return bytes;
}

std::string encodeNanoVdb(const std::vector<VolumeGrid>& grids, const VolumeMetadata& meta, const VolumeOptions& o) {
  std::vector<nanovdb::GridHandle<nanovdb::HostBuffer>> handles;
  for (const openvdb::GridBase::Ptr& g : buildGrids(grids, o)) {
    handles.push_back(nanovdb::openToNanoVDB(g));
    if (!handles.back()) throw std::runtime_error("NanoVDB cannot hold the grid '" + g->getName() + "'");
  }
  // writeGrids seeks past its header before writing it, which a string
  // stream allows only over bytes it holds: hold the header's size first.
  nanovdb::io::Segment segment(nanovdb::io::Codec::NONE);
  for (const auto& h : handles) segment.add(h);
  std::stringstream os(std::string(segment.memUsage(), '\0'),
                       std::ios_base::in | std::ios_base::out | std::ios_base::binary);
  nanovdb::io::writeGrids<nanovdb::HostBuffer, std::vector>(os, handles, nanovdb::io::Codec::NONE);
  if (!os) throw std::runtime_error("the NanoVDB grids could not be serialised");
  return os.str();
}

namespace {

// No buffer of a valid volume's reading is near this: a leaf holds 512 voxels.
constexpr size_t kMaxReaderAllocation = size_t(64) << 20;
constexpr const char* kClaimsTooMuch =
    "the file is damaged: a length stored in it asks for more than 64 MiB at once (a valid volume never does)";

}  // namespace

// In a child process, as readVdbVelocity: opening a damaged file reads its
// grids' topology, which OpenVDB misreads. The answer: "1" and the time's
// bytes, "0" (no time), or "E" and the error.
bool readVdbTime(const std::string& path, double* time, bool* has, std::string* error) {
  initialiseOnce();
  std::string answer;
  if (!runIsolated(
          [&]() -> std::string {
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
          },
          readerLimits(10.0), &answer, error))
    return false;
  if (answer.empty() || answer[0] == 'E') {
    *error = answer.empty() ? std::string("the file is damaged: its reader gave no answer") : answer.substr(1);
    return false;
  }
  *has = answer[0] == '1' && answer.size() == 1 + sizeof(double);
  if (*has) std::memcpy(time, answer.data() + 1, sizeof(double));
  return true;
}

namespace {

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
      openvdb::tools::copyToDense(*grid, dst, /*serial=*/true);  // (in the reader's child: no threads)
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

// The child's answer: ok, then the error or the volume, field by field.
template <class T>
void put(std::string* s, const T& v) {
  s->append(reinterpret_cast<const char*>(&v), sizeof v);
}
void putText(std::string* s, const std::string& t) {
  put<uint64_t>(s, t.size());
  s->append(t);
}
template <class T>
T take(const std::string& s, size_t* at) {
  if (s.size() - *at < sizeof(T)) throw std::runtime_error("the reader's answer is cut short");
  T v;
  std::memcpy(&v, s.data() + *at, sizeof v);
  *at += sizeof v;
  return v;
}
std::string takeText(const std::string& s, size_t* at) {
  const uint64_t n = take<uint64_t>(s, at);
  if (s.size() - *at < n) throw std::runtime_error("the reader's answer is cut short");
  std::string t = s.substr(*at, n);
  *at += n;
  return t;
}

std::string encodeAnswer(bool ok, const VelocityVolume& v, const std::string& error) {
  std::string s;
  put<uint8_t>(&s, ok);
  if (!ok) {
    putText(&s, error);
    return s;
  }
  putText(&s, v.grid);
  put(&s, v.staggered), put(&s, v.origin), put(&s, v.cells), put(&s, v.voxelSize), put(&s, v.indexOrigin);
  put(&s, v.hasTime), put(&s, v.hasDomain), put(&s, v.time), put(&s, v.domain);
  for (const std::vector<float>& c : v.values)
    putText(&s,
            c.empty() ? std::string() : std::string(reinterpret_cast<const char*>(c.data()), c.size() * sizeof(float)));
  return s;
}

bool decodeAnswer(const std::string& s, VelocityVolume* v, std::string* error) {
  size_t at = 0;
  if (!take<uint8_t>(s, &at)) {
    *error = takeText(s, &at);
    return false;
  }
  v->grid = takeText(s, &at);
  v->staggered = take<bool>(s, &at);
  v->origin = take<std::array<int, 3>>(s, &at);
  v->cells = take<std::array<int, 3>>(s, &at);
  v->voxelSize = take<double>(s, &at);
  v->indexOrigin = take<std::array<double, 3>>(s, &at);
  v->hasTime = take<bool>(s, &at);
  v->hasDomain = take<bool>(s, &at);
  v->time = take<double>(s, &at);
  v->domain = take<std::array<double, 3>>(s, &at);
  for (std::vector<float>& c : v->values) {
    const std::string b = takeText(s, &at);
    c.resize(b.size() / sizeof(float));
    if (!c.empty()) std::memcpy(c.data(), b.data(), c.size() * sizeof(float));
  }
  return true;
}

}  // namespace

// In a child process (render/isolated_read.h): a damaged file that makes
// OpenVDB write past a buffer ends the child, not the run.
bool readVdbVelocity(const std::string& path, VelocityVolume* out, std::string* error) {
  initialiseOnce();
  // 10 s of CPU and 1 s per 20 MB: a valid volume reads at hundreds of MB/s.
  std::error_code ec;
  const uintmax_t bytes = std::filesystem::file_size(path, ec);
  const double seconds = 10.0 + (ec ? 0.0 : double(bytes) / 20e6);
  std::string answer;
  if (!runIsolated(
          [&] {
            VelocityVolume v;
            std::string err;
            const bool ok = readVelocityHere(path, &v, &err);
            return encodeAnswer(ok, v, err);
          },
          readerLimits(seconds), &answer, error))
    return false;
  try {
    return decodeAnswer(answer, out, error);
  } catch (const std::exception& e) {
    *error = e.what();
    return false;
  }
}

bool readVdbFrameSummary(const std::string& path, VdbFrameSummary* out, std::string* error) {
  initialiseOnce();
  std::string answer;
  // The names, each ended by a newline, a NUL, then the density's values.
  const auto work = [&]() -> std::string {
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
  };
  if (!runIsolated(work, readerLimits(60.0), &answer, error)) return false;
  const size_t nul = answer.find('\0');
  if (answer.empty() || answer[0] != 'N' || nul == std::string::npos || answer.size() < nul + 1 + 3 * sizeof(double)) {
    *error =
        answer.size() > 1 && answer[0] == 'E' ? answer.substr(1) : "the file is damaged: its reader gave no answer";
    return false;
  }
  out->grids.clear();
  for (size_t at = 1; at < nul;) {
    const size_t end = answer.find('\n', at);
    out->grids.push_back(answer.substr(at, end - at));
    at = end + 1;
  }
  const size_t at = nul + 1 + 3 * sizeof(double);
  std::memcpy(out->domain.data(), answer.data() + nul + 1, 3 * sizeof(double));
  out->density.resize((answer.size() - at) / 4);
  std::memcpy(out->density.data(), answer.data() + at, out->density.size() * 4);
  return true;
}

}  // namespace morphoflow
