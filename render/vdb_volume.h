// OpenVDB and NanoVDB volumes of a frame, for Blender, Houdini and GPU
// renderers. Only vdb_volume.cpp includes OpenVDB (it takes long to compile).
//
// Every grid has a linear transform with voxel size = its cell size and index
// (0,0,0) at the first cell's centre, so a grid of n cells fills [0, n h] in
// world space; a 2D field is one voxel thick. Voxels within `tolerance` of
// the background (0) are inactive. Files are Blosc-compressed.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace morphoflow {

struct VolumeGrid {
  enum class Kind {
    Scalar,     // a FloatGrid
    FogVolume,  // a FloatGrid of class fog volume (the density)
    Vector,     // a Vec3SGrid, vector type contravariant-relative (velocity)
    Staggered,  // the same, of class staggered: component a of voxel v on v's lower face along a (MAC velocity)
    LevelSet,   // `values` is a solid mask (nonzero inside): written as a narrow-band level set
    Color,      // a Vec3SGrid of linear RGB in [0, 1], vector type invariant (Blender's `color`)
  };
  std::string name;
  Kind kind = Kind::Scalar;
  std::array<int, 3> cells{1, 1, 1};        // nz = 1 for a 2D field
  double voxelSize = 1.0;
  std::vector<std::vector<float>> values;  // one component (x fastest), or three for a vector
};

struct VolumeMetadata {
  long frame = 0, step = 0;
  double time = 0.0, dt = 0.0;
  std::string scene, version, settingsHash, units;
  std::array<double, 3> domain{0.0, 0.0, 0.0};  // the domain's extent (0: not written)
};

struct VolumeOptions {
  float tolerance = 0.0f;  // |value - background| <= tolerance: inactive
  bool half = false;       // floats saved as half
  // Shared topologies: the active voxels (x fastest; nonzero: active) of
  // every scalar, vector and colour grid of a mask's cells, one topology for
  // all of them, in place of `tolerance` (a smoke frame is active where
  // there is smoke, on the fluid's grid and on the chemicals').
  struct ActiveMask {
    std::array<int, 3> cells{0, 0, 0};
    std::vector<uint8_t> on;
  };
  std::vector<ActiveMask> active;
};

// A mask grid's active voxels: those whose first component is nonzero.
VolumeOptions::ActiveMask activeWhere(const VolumeGrid& mask);

// Half's range (65504) for output.vdb_half: a value beyond it would be read
// back as infinity, so it is set at the limit instead. The count of values
// set, per grid that had any (level sets are left as they are).
std::map<std::string, uintmax_t> clampToHalf(std::vector<VolumeGrid>* grids);

// The .vdb file's bytes. Its UUID is derived from its content, so the same
// fields give the same bytes (a resumed run writes what an uninterrupted one does).
std::string encodeVdb(const std::vector<VolumeGrid>& grids, const VolumeMetadata& meta, const VolumeOptions& options);
// The same grids as a NanoVDB file (.nvdb), uncompressed, for GPU renderers.
std::string encodeNanoVdb(const std::vector<VolumeGrid>& grids, const VolumeMetadata& meta,
                          const VolumeOptions& options);

// Reading a .vdb file runs the program morphoflow-vdb-reader (built beside the
// library) in a process of its own: render/isolated_read.h.

// A velocity read back from a .vdb file: the grid `vel_mac` (staggered, as
// morphoflow writes it with output.vdb_mac_velocity) if the file has one,
// else `vel` (any Vec3 float grid, cell-centred), densely over its active
// voxels' bounding box.
struct VelocityVolume {
  std::string grid;                      // the grid read
  bool staggered = false;
  std::array<int, 3> origin{0, 0, 0};    // index of the box's first voxel
  std::array<int, 3> cells{0, 0, 0};     // the box's voxels per axis (all 0: no active voxel)
  double voxelSize = 1.0;
  std::array<double, 3> indexOrigin{};   // world position of index (0, 0, 0)
  std::array<std::vector<float>, 3> values;  // per component, x fastest over the box
  bool hasTime = false, hasDomain = false;
  double time = 0.0;
  std::array<double, 3> domain{};        // the writer's domain_size metadata
};

// The box of a velocity volume's active voxels may span at most this many
// cells (512^3: it is read densely, 24 bytes a cell).
constexpr long kMaxVelocityCells = 1L << 27;
// False and a message (what is missing, or what OpenVDB said) when the file
// cannot be read, has no velocity grid, or spans more than kMaxVelocityCells.
bool readVdbVelocity(const std::string& path, VelocityVolume* out, std::string* error);
// Each file's `time` metadata, without reading its grids, one reader for all
// of them. False, *error and *failed (the index of the file at fault) when a
// file cannot be read; *out holds the times of the files before it.
struct VdbTime {
  bool has = false;  // false: the file has no `time` metadata
  double time = 0.0;
};
bool readVdbTimes(const std::vector<std::string>& paths, std::vector<VdbTime>* out, size_t* failed, std::string* error);

// A frame's grids by name and the active values of its `density` grid, for
// the Blender set-up (app's `blender` command) to choose its density scale.
struct VdbFrameSummary {
  std::vector<std::string> grids;
  std::vector<float> density;                   // the active voxels' values (empty without a `density` grid)
  std::array<double, 3> domain{0.0, 0.0, 0.0};  // its domain_size metadata (0: none)
};
bool readVdbFrameSummary(const std::string& path, VdbFrameSummary* out, std::string* error);

}  // namespace morphoflow
