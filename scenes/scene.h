// A scene as plain settings: everything a run needs, resolved from a TOML
// file plus --set overrides. Owned by the layers below (fluid, render).
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "core/backend.h"
#include "core/error.h"
#include "core/spatial_field.h"
#include "coupling/coupling_choices.h"
#include "fluid/fluid_settings.h"
#include "rd/brush_strokes.h"
#include "rd/generalized_diffusion.h"
#include "rd/rd_settings.h"
#include "scenes/field_catalogue.h"
#include "scenes/timeline.h"

namespace morphoflow {

struct TimeSettings {
  double dt = 0.01;        // fixed step, or the largest step when cfl > 0
  long steps = 0;          // exactly one of steps / duration is used
  double duration = 0.0;
  double cfl = 0.0;        // > 0: adaptive dt = min(dt, cfl h / |u|max)
  // > 0: the run ends at the first frame where the velocity's relative
  // change per unit time since the frame before is below this (run/steady_state.h).
  double untilSteady = 0.0;
  // A run of a duration ends once it is this close to the end (run/run_clock.h).
  static constexpr double kEndTolerance = 1e-12;
  // The duration of a run until steady that gives neither steps nor duration.
  static constexpr double kSteadyCap = 1000.0;
  // The most steps a run may take (a step count, a duration over dt, or a
  // CFL limit's steps: run/run_driver.cpp).
  static constexpr long kMaxSteps = 100'000'000;
};

struct OutputSettings {
  int every = 10;                  // steps between frames
  bool images = true;
  bool fields = false;
  bool vdb = false;                 // DIR/vdb/<name>.NNNNNN.vdb every frame
  std::string vdbDensity;           // the field in the "density" grid (default: field), or an expression of fields
  // A patterned smoke scene's default density: the smoke shaped by the shown
  // species (kernels/pattern_density.inc), unless output.vdb_density is given.
  bool patternDensity = false;
  double patternContrast = 1.0;        // output.pattern_contrast: 0 the smoke as is, 1 none between the features
  std::vector<std::string> vdbFields;  // fluid scalars as grids of their own
  double vdbTolerance = 0.0;        // |value| <= this: inactive voxel (with [smoke]: of the smoke, in every grid)
  bool vdbSparse = false;  // with [smoke]: every grid active where the smoke exceeds vdbTolerance (false: every voxel)
  bool vdbColor = false;            // a `color` grid: the palette applied to output.field (default with [smoke])
  bool vdbHalf = false;             // floats saved as half
  bool nanovdb = false;             // also DIR/vdb/<name>.NNNNNN.nvdb
  bool vdbMacVelocity = false;      // also `vel_mac`: the MAC face velocities exactly (staggered)
  bool video = false;               // encode the PNG frames into OUT/<name>.mp4 (ffmpeg)
  int fps = 30;                     // video frames per second
  std::string field = fields::kVorticity;  // a name of the catalogue (scenes/field_catalogue.h)
  std::string colormap = "coolwarm"; // a named palette, or "red-green" (two species)
  std::vector<std::array<uint8_t, 3>> gradient;  // custom palette stops (overrides colormap)
  std::string format = "png";      // image frames: png | exr
  bool autoRange = true;
  double range[2] = {0.0, 1.0};
  int slice = -1;                  // 3D: z slice for images (-1 = middle)
  std::string view = "slice";      // 3D: "volume" (ray marched, the default) or "slice"; 2D: "slice"
  int imageSize = 512;             // frames are at least this many pixels wide
  double emission = 0.0;           // 3D smoke: the lit preview's blackbody emission strength (render/lit_volume.h)
  bool normalMap = false;           // 2D: DIR/normals/NNNNNN.png and DIR/height/NNNNNN.exr of the shown field
  double normalStrength = 4.0;      // normal map slope per unit of height (0..1 over the range) per cell
  int checkpointEvery = 10;        // frames between checkpoints (0: only at the end and on a stop)
};

struct ProbeSettings {
  bool centerlines = false;        // cavity velocity profiles
  bool forces = false;             // drag and lift on the obstacles
  double strouhalStart = -1.0;     // time from which the lift period is measured (-1 = half the run)
  double referenceLength = 1.0;    // for Reynolds number, coefficients, Strouhal number
  double referenceSpeed = 1.0;
  double referenceArea = 1.0;      // frontal area of the obstacle (length in 2D)
};

struct DyeSettings {
  std::string initial = "none";    // none | stripes | checker
  int stripes = 8;                 // stripes across the inflow / the domain
};

// Initial state of a reaction-diffusion layer.
struct RDInitial {
  std::vector<double> values;        // uniform state per species (empty: the model's)
  std::vector<double> noise;         // +- uniform noise amplitude per species
  bool randomRange = false;          // every species uniform in [range0, range1] (seed 002)
  double range[2] = {0.0, 8.0};
  double square = 0.0;               // side of a central square, as a fraction of the domain (Pearson)
  std::vector<double> squareValues;  // species values inside it
};

// A spatial field from the scene file, with where it was written (for errors at run time).
struct SceneField {
  SpatialField field;
  SourceLocation where;
  std::string key;
};

// Cells held at fixed species values for the whole run (seed 004 fig. 20).
struct RDFixedRegion {
  SceneField where;                  // nonzero inside the region
  std::vector<int> species;          // the species it holds (default: all)
  std::vector<double> values;        // one per held species
};

// Inhomogeneous anisotropic diffusion, [rd.anisotropy] (seed 004 eq. 11-19):
// sigma = lambda2 I + (lambda1 - lambda2) a a^T per cell, a from theta (xy
// plane) or a direction vector field.
struct RDAnisotropy {
  bool enabled = false;
  SceneField lambda1, lambda2;        // principal diffusivities along and across a (> 0)
  SceneField theta;                   // angle of a in the xy plane, radians (when direction is empty)
  bool thetaFromStrokes = false;      // theta = "strokes": the painted strokes' direction + strokeAngle
  double strokeAngle = 0.0;
  std::vector<SceneField> direction;  // or a, one field per axis (normalised per cell; zero = isotropic)
  bool directionFromVelocity = false; // direction = "velocity": a = u / |u| of the given velocity
  std::vector<int> species;           // the anisotropic species (empty: all)
  double shape = 0.0;                 // eq. 18's I (0: off)
  int shapeSpecies = 0;               // whose gradient shapes the tensor
};

// Kim & Lin's cosine-lobe anisotropy, [rd.cosine_lobes] (seed 001 eq. 14-17):
// a species diffuses by div(d a(theta) grad), theta its own gradient's angle.
struct RDCosineLobes {
  bool enabled = false;
  std::vector<double> speeds;         // a_n per lobe (eq. 16), or a1, a2 (eq. 15)
  bool witkinKass = false;            // eq. 15
  SceneField theta0;                  // rotation, radians (a field)
  bool theta0FromStrokes = false;     // theta0 = "strokes": lobe 1 along the strokes' direction + strokeAngle
  double strokeAngle = 0.0;
  std::vector<int> species;           // the lobed species (empty: all)
};

// McGraw's generalized (non-Gaussian) diffusion, [rd.generalized] (seed 000):
// the Kramers-Moyal tensors of rank 2 to 4 (a Table 2 preset, components, a rotation).
struct RDGeneralized {
  bool enabled = false;
  KramersMoyalTensors tensors;        // after the rotation
  std::string preset;                 // Table 2's column, or "" (components given)
  double rotation = 0.0;              // radians
  bool savitzkyGolaySecond = false;   // second derivatives by Savitzky-Golay too (else central differences)
  std::vector<int> species;           // empty: all
  double maxSpectralRadius = 1.05;    // a step whose spectral radius exceeds this is refused
  SourceLocation where;
};

// A brush stroke, [[rd.strokes]] (seed 001 sec. 6): its direction may steer
// the anisotropy, and it may deposit chemical (the cells under it held fixed).
struct RDStroke {
  BrushStroke stroke;
  std::vector<int> species;           // deposited species (empty: none)
  std::vector<double> values;         // one per deposited species
  SourceLocation where;
  std::string key;
  double start = 0.0;                 // when it is painted (the scene's timeline)
};

struct RDScene {
  bool enabled = false;
  RDSettings settings;
  RDInitial initial;
  std::vector<std::pair<int, SceneField>> initialMaps;  // species index -> its initial field
  std::vector<std::pair<int, SceneField>> parameterMaps;  // parameter index -> its field ([rd.maps])
  std::vector<int> speedMaps;        // parameters mapped from the given velocity's speed ([rd.maps] P = "speed")
  std::vector<std::pair<int, double>> perturb;  // parameter index, Gaussian sigma in percent (seed 004 sec. 3.1)
  std::vector<RDFixedRegion> fixed;
  std::vector<RDStroke> strokes;
  RDAnisotropy anisotropy;
  RDCosineLobes lobes;
  RDGeneralized generalized;
  // Whether any stroke deposits chemical (holds its cells).
  bool strokesDeposit() const {
    for (const RDStroke& s : strokes)
      if (!s.species.empty()) return true;
    return false;
  }
  // Whether every step is the plain explicit Euler step (rd_settings.h:
  // x += dt (R(x) + d lap x)) with uniform parameters and nothing held, frozen,
  // steered or walled: the one test both backends' fast explicit paths take
  // (rd/fused_explicit.h on the CPU, gpu/gpu_explicit_rd.h on the GPU).
  bool plainExplicit() const {
    return settings.integrator == RDIntegrator::ExplicitEuler && settings.boundary != RDBoundary::Dirichlet &&
           settings.frozen.empty() && parameterMaps.empty() && perturb.empty() && speedMaps.empty() && fixed.empty() &&
           !strokesDeposit() && !anisotropy.enabled && !lobes.enabled;
  }
  int coarseLevels = 0;              // coarse-to-fine: grids 2^L, ..., 2 times coarser first (seed 002, 000)
  long coarseSteps = 0;              // steps on each coarse grid
  bool coarseScaleDt = false;        // a grid 2^l times coarser steps 4^l dt (explicit limits scale with h^2)
};

// [coupling]: a fluid carrying a reaction-diffusion layer (seed 001 sec. 5).
struct CouplingScene {
  bool enabled = false;
  CouplingMode mode = CouplingMode::ARD;
  ChemicalInterpolation interpolation = ChemicalInterpolation::Linear;
  double rdTimeScale = 1.0;             // RD time per unit of fluid time
  std::vector<double> inflowValues;     // per species, chemical entering through inflow sides
  std::vector<double> solidValues;      // per species, inside obstacles
  // With [smoke]: the layer reacts only where the smoke exceeds smokeMask
  // (< 0: everywhere); elsewhere it is held at smokeValues (its rest state).
  double smokeMask = -1.0;
  std::vector<double> smokeValues;
};

// [velocity]: a given velocity carrying the [rd] layer instead of a fluid
// (flow visualisation, seed 004 sec. 3, fig. 24).
struct VelocityScene {
  bool enabled = false;
  std::vector<std::string> field;    // one expression per axis in x, y, z (domain units) and t
  std::string vdb;                   // or a VDB sequence: a path whose '#'s stand for the frame number
  bool python = false;               // or the Python module's Simulation.set_velocity (an array or a callable)
  double frameTime = 0.0;            // time between VDB frames that carry no `time` metadata
  double speedRange[2] = {0.0, 1.0}; // [rd.maps] P = "speed": P = lo + (hi - lo) |u| / referenceSpeed
  double referenceSpeed = 0.0;       // 0: the largest speed of the first velocity sampled
  SourceLocation where;              // of the field or vdb key, for errors at run time
  std::string key;
};

// A file a scene reads besides itself (an image, a frame of a velocity sequence).
struct SceneInput {
  std::string path;
  SourceLocation where;
  std::string key;
};

// A numeric key as the reader checked it: its range and its value(s).
struct KeyRange {
  double lo = 0.0, hi = 0.0;
  bool loOpen = false;
  bool array = false;
  std::vector<double> values;  // one, or an array's
};

struct Scene {
  std::string path;                // the file it came from
  std::vector<SceneInput> inputs;  // the files it reads
  std::string name;
  int dimension = 2;
  uint64_t seed = 1;
  FluidSettings fluid;
  TimeSettings time;
  OutputSettings output;
  ProbeSettings probes;
  DyeSettings dye;
  bool hasFluid = true;            // false for reaction-diffusion-only scenes
  RDScene rd;
  CouplingScene coupling;          // rd.enabled && (hasFluid || velocity.enabled)
  VelocityScene velocity;
  double reynolds = 0.0;           // resolved Re = U L / nu
  std::string resolvedJson;        // the scene as resolved (JSON text), for run.json
  SceneTimeline timeline;          // what changes during the run (keyframes, deposits, timed elements)
  GpuPrecision gpuPrecision = GpuPrecision::Float;  // gpu.precision
  std::map<std::string, KeyRange> numericKeys;
  std::set<std::string> givenKeys;  // the keys the file or an override gave (not defaulted)  // every numeric key read,
                                    // with its range (the studio's controls)
  long totalSteps() const;         // resolved from steps or duration/dt
};

}  // namespace morphoflow
