// `morphoflow blender OUT_DIR`: the Blender set-up of a run's VDB sequence,
// OUT_DIR/blender_scene.py (app/blender_scene_script.h), its header filled
// with the run's facts: the sequence, the grids, the density scale the lit
// preview would choose for its last frame, the preview's camera and lights.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <regex>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "app/blender_scene_script.h"
#include "app/commands.h"
#include "core/error.h"
#include "core/output_file.h"
#include "render/lit_volume.h"
#include "render/vdb_volume.h"
#include "render/volume_camera.h"

namespace morphoflow {

namespace {

namespace fs = std::filesystem;

// The lights' strengths and the exposure in Blender's units (a sun's
// irradiance, the world's strength, stops of Filmic's view), set so that the
// shipped patterned plume reads in Blender as in the lit preview (docs/vfx.md,
// "Legibility").
constexpr double kKeyStrength = 12.0, kSkyStrength = 1.5, kExposure = 3.0;

struct BlenderOptions {
  std::string out;
};

struct Sequence {
  std::string name;             // NAME of NAME.NNNNNN.vdb
  std::vector<fs::path> files;  // in frame order
};

Sequence vdbSequence(const fs::path& dir) {
  const fs::path vdb = dir / "vdb";
  const std::string hint = "run the scene with output.vdb = true (`--set output.vdb=true`) and give its --out folder";
  std::error_code ec;
  if (!fs::is_directory(vdb, ec))
    throw UserError({dir.string(), 0, 0}, "", "no VDB sequence: " + vdb.string() + " is not a folder", hint);
  const std::regex numbered(R"((.+)\.(\d{6})\.vdb)");
  std::vector<std::pair<long, fs::path>> found;
  Sequence s;
  for (const auto& e : fs::directory_iterator(vdb, ec)) {
    std::smatch m;
    const std::string file = e.path().filename().string();
    if (!std::regex_match(file, m, numbered)) continue;
    if (!s.name.empty() && m[1] != s.name)
      throw UserError({vdb.string(), 0, 0}, "", "two sequences in one folder: " + s.name + " and " + m[1].str(),
                      "keep one scene's volumes in " + vdb.string());
    s.name = m[1];
    found.emplace_back(std::stol(m[2]), e.path());
  }
  if (found.empty()) throw UserError({vdb.string(), 0, 0}, "", "no NAME.NNNNNN.vdb files", hint);
  std::sort(found.begin(), found.end());
  for (size_t k = 1; k < found.size(); ++k)
    if (found[k].first != found[0].first + long(k))
      throw UserError(
          {found[k].second.string(), 0, 0}, "",
          fmt::format("the sequence has a gap: frame {} follows frame {}", found[k].first, found[k - 1].first),
          "Blender reads consecutive frames; write every frame, or remove the ones after the gap");
  for (const auto& f : found) s.files.push_back(f.second);
  return s;
}

// A value of run.json's resolved scene, or `def` when the scene left it out.
double resolved(const nlohmann::json& run, const char* table, const char* key, double def) {
  const nlohmann::json* r = run.contains("resolved") ? &run["resolved"] : nullptr;
  if (!r || !r->contains(table) || !(*r)[table].contains(key) || !(*r)[table][key].is_number()) return def;
  return (*r)[table][key].get<double>();
}

std::string vec(const std::array<double, 3>& v) { return fmt::format("({:.9g}, {:.9g}, {:.9g})", v[0], v[1], v[2]); }

std::string header(const Sequence& s, const VdbFrameSummary& last, const nlohmann::json& run) {
  std::array<double, 3> domain = last.domain;
  if (!(domain[0] > 0)) throw std::runtime_error("no domain_size");
  if (!(domain[2] > 0)) domain[2] = domain[0] / 1024.0;  // a 2D run's one voxel: a thin slab
  // The preview's camera in domain units (render/volume_camera.h).
  const VolumeCamera cam(IVec<3>{1, 1, 1});
  const double radius = 0.5 * std::sqrt(domain[0] * domain[0] + domain[1] * domain[1] + domain[2] * domain[2]);
  const std::array<double, 3> centre{0.5 * domain[0], 0.5 * domain[1], 0.5 * domain[2]};
  std::array<double, 3> eye;
  for (int a = 0; a < 3; ++a)
    eye[size_t(a)] = centre[size_t(a)] + cam.towardEye[size_t(a)] * 1.02 * radius / std::sin(15.0 * M_PI / 180.0);
  const double side = *std::max_element(domain.begin(), domain.end());
  const double density = extinctionPerLength(densityQ90(last.density.data(), last.density.size()), side);
  std::string grids;
  for (const std::string& g : last.grids) grids += fmt::format("{}\"{}\"", grids.empty() ? "" : ", ", g);
  return fmt::format(
      "\"\"\"Blender set-up of the morphoflow run in this folder (`morphoflow blender`).\n\n"
      "  blender -b --python blender_scene.py -- --render                 # the animation, into render/frame_####.png\n"
      "  blender -b --python blender_scene.py -- --render --frame last    # one frame (or --frame N)\n"
      "  blender -b --python blender_scene.py -- --save scene.blend       # the set-up as a .blend file\n"
      "  blender --python blender_scene.py                                # open it in Blender\n\n"
      "Options after --: --resolution PX (width), --samples S, --output PREFIX (Blender's output path:\n"
      "'#' is the frame number, else it is appended). docs/vfx.md of morphoflow describes the look.\"\"\"\n"
      "RUN = {{\n"
      "    \"name\": \"{}\",\n"
      "    \"first\": \"vdb/{}\",\n"
      "    \"frames\": {},\n"
      "    \"grids\": [{}],\n"
      "    \"domain\": {},\n"
      "    \"density\": {:.9g},  # extinction per unit of density per scene unit (the preview's, for the last frame)\n"
      "    \"ambient\": {:.9g},\n"
      "    \"emission\": {:.9g},\n"
      "    \"kelvin_at_ambient\": {:.9g},\n"
      "    \"kelvin_per_unit\": {:.9g},\n"
      "    \"to_key\": {},\n"
      "    \"key_colour\": {},\n"
      "    \"key_strength\": {:.9g},\n"
      "    \"sky_colour\": {},\n"
      "    \"sky_strength\": {:.9g},\n"
      "    \"exposure\": {:.9g},\n"
      "    \"backdrop\": {},\n"
      "    \"centre\": {},\n"
      "    \"eye\": {},\n"
      "    \"field_of_view\": 30.0,\n"
      "    \"resolution\": {},\n"
      "    \"fps\": {},\n"
      "}}\n",
      s.name, s.files.front().filename().string(), s.files.size(), grids, vec(domain), density,
      resolved(run, "smoke", "ambient", 0.0), resolved(run, "output", "emission", 0.0), kKelvinAtAmbient,
      kKelvinPerUnit, vec(keyLightDirection()), vec(kKeyLight), kKeyStrength, vec(kSkyLight), kSkyStrength, kExposure,
      vec(kBackdrop), vec(centre), vec(eye), int(resolved(run, "output", "image_size", 512)),
      int(resolved(run, "output", "fps", 30)));
}

int blenderCommand(const BlenderOptions& o) {
  const fs::path dir(o.out);
  const Sequence s = vdbSequence(dir);
  VdbFrameSummary last;
  std::string err;
  if (!readVdbFrameSummary(s.files.back().string(), &last, &err))
    throw UserError({s.files.back().string(), 0, 0}, "", "cannot read: " + err, "rerun the scene to write it again");
  if (std::find(last.grids.begin(), last.grids.end(), "density") == last.grids.end() || !(last.domain[0] > 0))
    throw UserError({s.files.back().string(), 0, 0}, "",
                    "not a morphoflow frame: it lacks a density grid or domain_size",
                    "give the --out folder of a morphoflow run with output.vdb = true");
  nlohmann::json run = nlohmann::json::object();
  if (std::ifstream in(dir / "run.json"); in) run = nlohmann::json::parse(in, nullptr, false);
  if (run.is_discarded()) run = nlohmann::json::object();
  const fs::path script = dir / "blender_scene.py";
  writeFileAtomically(script, header(s, last, run) + kBlenderSceneBody);
  std::cout << fmt::format("{}: {} frames of {} ({}); render them with\n  blender -b --python {} -- --render\n",
                           script.string(), s.files.size(), s.name, fmt::join(last.grids, ", "), script.string());
  return 0;
}

}  // namespace

void addBlenderCommand(CLI::App& app, Commands* commands) {
  auto o = std::make_shared<BlenderOptions>();
  CLI::App* cmd =
      app.add_subcommand("blender", "write OUT_DIR/blender_scene.py: a run's VDB sequence set up in Blender");
  cmd->add_option("out", o->out, "a run's --out folder (with vdb/)")->required();
  commands->add(cmd, [o] { return blenderCommand(*o); });
}

}  // namespace morphoflow
