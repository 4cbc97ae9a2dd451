#include "render/vdb_volume.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <mutex>
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

#include "render/isolated_read.h"
#include "render/velocity_answer.h"

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

// The reader's answers for `paths` in `mode` (render/vdb_read_here.h), one
// process for all of them, allowed `cpuSeconds`. False and *error when it
// stopped: *answers then holds those it gave, so the file it stopped at is
// paths[answers->size()].
bool readerAnswers(const char* mode, const std::vector<std::string>& paths, double cpuSeconds,
                   std::vector<std::string>* answers, std::string* error) {
  std::vector<std::string> argv{MORPHOFLOW_VDB_READER, mode};
  argv.insert(argv.end(), paths.begin(), paths.end());
  std::string out;
  const bool ok = runIsolated(argv, readerLimits(cpuSeconds), &out, error);
  *answers = takeRecords(out);
  if (ok && answers->size() != paths.size()) {
    *error = "the file is damaged: its reader's result was cut short";
    return false;
  }
  return ok;
}

}  // namespace

bool readVdbTimes(const std::vector<std::string>& paths, std::vector<VdbTime>* out, size_t* failed,
                  std::string* error) {
  out->clear();
  // A reader for each 256 files, so that the arguments stay far below the
  // system's limit (ARG_MAX) however long the sequence.
  constexpr size_t kFilesPerReader = 256;
  for (size_t first = 0; first < paths.size(); first += kFilesPerReader) {
    const std::vector<std::string> some(paths.begin() + long(first),
                                        paths.begin() + long(std::min(paths.size(), first + kFilesPerReader)));
    std::vector<std::string> answers;
    // 10 s of CPU, and a tenth of a second per file: a valid file's metadata reads in milliseconds.
    const bool ok = readerAnswers("time", some, 10.0 + 0.1 * double(some.size()), &answers, error);
    for (const std::string& a : answers) {
      *failed = out->size();
      if (a.empty() || a[0] == 'E' || (a[0] == '1' && a.size() != 1 + sizeof(double))) {
        *error = a.size() > 1 && a[0] == 'E' ? a.substr(1) : "the file is damaged: its reader gave no answer";
        return false;
      }
      VdbTime t;
      t.has = a[0] == '1';
      if (t.has) std::memcpy(&t.time, a.data() + 1, sizeof(double));
      out->push_back(t);
    }
    *failed = out->size();
    if (!ok) return false;
  }
  return true;
}

bool readVdbVelocity(const std::string& path, VelocityVolume* out, std::string* error) {
  // 10 s of CPU and 1 s per 20 MB: a valid volume reads at hundreds of MB/s.
  std::error_code ec;
  const uintmax_t bytes = std::filesystem::file_size(path, ec);
  std::vector<std::string> answers;
  if (!readerAnswers("velocity", {path}, 10.0 + (ec ? 0.0 : double(bytes) / 20e6), &answers, error)) return false;
  return decodeVelocityAnswer(answers[0], out, error);
}

bool readVdbFrameSummary(const std::string& path, VdbFrameSummary* out, std::string* error) {
  std::vector<std::string> answers;
  if (!readerAnswers("summary", {path}, 60.0, &answers, error)) return false;
  const std::string& answer = answers[0];
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
