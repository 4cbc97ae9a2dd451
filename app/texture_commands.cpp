#include "app/texture_commands.h"

#include <algorithm>
#include <memory>
#include <filesystem>
#include <iostream>
#include <stdexcept>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "app/commands.h"
#include "app/option_checks.h"
#include "core/error.h"
#include "core/output_file.h"
#include "rd/generalized_diffusion.h"
#include "rd/variogram.h"
#include "render/colormap.h"
#include "render/field_dump.h"
#include "render/field_image.h"
#include "render/image_io.h"
#include "render/legibility.h"
#include "render/polar_plot.h"
#include "scenes/scene_loader.h"

namespace morphoflow {

namespace {

const char* kDirectionNames[Variogram::kDirections] = {"(1,0)", "(0,1)", "(1,1)", "(1,-1)"};

void printReg(const std::string& what, const Variogram& v) {
  std::cout << fmt::format("{}: variance {:.6g}, REG {:.4f} (at spacing {} x {})\n", what, v.variance, v.reg,
                           v.regLag, kDirectionNames[v.regDirection]);
}

// A rendered element's legibility (render/legibility.h), one measure a line.
int legibilityCommand(const AnalyzeOptions& o) {
  int w = 0, h = 0;
  std::vector<uint8_t> rgb;
  std::string err;
  if (!readRgb8(o.file, &w, &h, &rgb, &err))
    throw UserError({o.file, 0, 0}, "", "cannot read: " + err, "give a rendered frame (PNG, EXR)");
  const Legibility m = measureLegibility(rgb, w, h);
  std::cout << fmt::format("plume_pixels {} ({:.1f}% of {} x {})\nmedian_luminance {:.4f}\nband_contrast {:.4f}\n",
                           m.plumePixels, 100.0 * m.plumeFraction, w, h, m.medianLuminance, m.bandContrast);
  return 0;
}

}  // namespace

int analyzeCommand(const AnalyzeOptions& o) {
  if (o.legibility) return legibilityCommand(o);
  if (!o.csv.empty()) checkOutputFile(o.csv, "--csv");
  FieldDump d;
  std::string err;
  if (!readFieldDump(o.file, &d, &err))
    throw UserError({o.file, 0, 0}, "", "cannot read: " + err, "give a PNG/EXR image or a fields/NNNNNN.exr dump");
  size_t c = 0;
  if (!o.channel.empty()) {
    auto it = std::find(d.names.begin(), d.names.end(), o.channel);
    if (it == d.names.end())
      throw UserError({"--channel", 0, 0}, "", "no channel '" + o.channel + "' in " + o.file,
                      fmt::format("channels: {}", fmt::join(d.names, ", ")));
    c = size_t(it - d.names.begin());
  }
  const int nx = d.resolution[0], ny = d.resolution[1], nz = d.resolution.size() > 2 ? d.resolution[2] : 1;
  if (o.slice >= nz) throw UserError({"--slice", 0, 0}, "", fmt::format("the field has {} z slices", nz));
  const int z = o.slice >= 0 ? o.slice : nz / 2;
  // A colour image without --channel is analysed by its luminance (Rec. 709).
  if (o.channel.empty() && d.names.size() >= 3 && d.names[0] == "R" && d.names[1] == "G" && d.names[2] == "B") {
    for (size_t i = 0; i < d.channels[0].size(); ++i)
      d.channels[0][i] = 0.2126f * d.channels[0][i] + 0.7152f * d.channels[1][i] + 0.0722f * d.channels[2][i];
    d.names[0] = "luminance";
  }
  const std::vector<float>& ch = d.channels[c];
  std::vector<double> t(ch.begin() + long(z) * nx * ny, ch.begin() + long(z + 1) * nx * ny);
  if (nx < 4 || ny < 4)
    throw UserError({o.file, 0, 0}, "",
                    fmt::format("the image is {} x {}: a variogram needs at least 4 x 4 pixels", nx, ny),
                    "analyse a larger image");
  if (o.maxLag >= std::max(nx, ny))
    throw UserError({"--max-lag", 0, 0}, "", fmt::format("the lag must be below the field's size ({} x {})", nx, ny));
  Variogram v = variogram(t, nx, ny, {.maxLag = o.maxLag, .periodic = o.periodic});
  if (!(v.variance > 0))
    throw UserError({o.file, 0, 0}, "",
                    fmt::format("channel {} is constant (or not finite): it has no pattern to measure",
                                d.names[c].empty() ? "0" : d.names[c]),
                    "analyse a frame with a pattern, or pick another --channel");
  std::cout << fmt::format("{}: {} x {}{}, channel {}\n", o.file, nx, ny,
                           nz > 1 ? fmt::format(" (z slice {} of {})", z, nz) : "",
                           d.names[c].empty() ? "0" : d.names[c]);
  printReg("variogram (seed 003 eq. 4-5, normalised by the variance)", v);
  if (!o.csv.empty()) {
    std::string s = "lag,v_10,v_01,v_11,v_1m1\n";
    for (size_t l = 0; l < v.v.size(); ++l)
      s += fmt::format("{},{:.8g},{:.8g},{:.8g},{:.8g}\n", l + 1, v.v[l][0], v.v[l][1], v.v[l][2], v.v[l][3]);
    writeFileAtomically(o.csv, s);
  }
  return 0;
}

int textonCommand(TextonOptions o) {
  checkOutputFile(o.out, "--out");
  TextonWalkSettings& s = o.walk;
  s.start = o.start == "regular"   ? TextonStart::Regular
            : o.start == "uniform" ? TextonStart::Uniform
                                   : TextonStart::Pulse;
  try {
    checkTextonWalk(s);
  } catch (const std::invalid_argument& e) {
    throw UserError({"texton", 0, 0}, "", e.what());
  }
  const std::string ext = std::filesystem::path(o.out).extension().string();
  if (ext != ".png" && ext != ".exr")
    throw UserError({"--out", 0, 0}, "", "the texture is written as .png or .exr, got '" + o.out + "'");
  const std::vector<std::array<int, 2>> at = textonWalk(s);
  const std::vector<double> img = renderTextons(at, s);
  std::string err;
  bool ok;
  if (ext == ".exr") {
    FieldDump d;
    d.resolution = {s.width, s.height};
    d.names = {"t"};
    d.channels = {std::vector<float>(img.begin(), img.end())};
    d.step = s.steps;
    ok = writeFieldDump(o.out, d, &err);
  } else {
    Grid<float, 2> g(IVec<2>(s.width, s.height));
    std::copy(img.begin(), img.end(), g.values().begin());
    FieldImageOptions io;
    io.palette = namedPalette("grayscale");
    io.autoRange = false;  // coverage is in [0, 1]
    int w, h;
    const std::vector<uint8_t> rgb = fieldToRgb<2>(g, io, &w, &h);
    ok = writeRgb8(o.out, s.width, s.height, rgb, &err);
  }
  if (!ok) throw UserError({o.out, 0, 0}, "--out", "cannot write the texture: " + err);
  std::cout << fmt::format("{}: {} of {} textons after {} steps of {} cells\n", o.out, at.size(), s.elements, s.steps,
                           s.stepSize);
  if (o.analyze) printReg("variogram", variogram(img, s.width, s.height));
  return 0;
}

int plotCommand(const PlotOptions& o) {
  checkOutputFile(o.out, "--out");
  if (o.what != "propagator")
    throw UserError({"plot", 0, 0}, "", "unknown plot '" + o.what + "'", "plots: propagator");
  const Scene scene = loadScene(o.scene, o.overrides);
  if (!scene.rd.generalized.enabled)
    throw UserError({o.scene, 0, 0}, "rd.generalized",
                    "the scene has no [rd.generalized] tensors, so its diffusion is Gaussian (a plain ellipse)",
                    "add [rd.generalized] preset = \"d\" (Table 2's columns a to f) or tensors d2, d3, d4");
  if (!(o.tau > 0) || !(o.radius > 0)) throw UserError({"--tau", 0, 0}, "", "--tau and --radius must be > 0");
  std::vector<double> p(1440);
  for (size_t k = 0; k < p.size(); ++k) {
    const double a = 2 * M_PI * double(k) / double(p.size());
    p[k] = gramCharlierPropagator(scene.rd.generalized.tensors, o.tau, o.radius * std::cos(a), o.radius * std::sin(a));
  }
  std::string err;
  if (!writeRgb8(o.out, o.size, o.size, polarPlotRgb(p, o.size), &err))
    throw UserError({o.out, 0, 0}, "--out", "cannot write the plot: " + err);
  const auto peak = std::max_element(p.begin(), p.end());
  std::cout << fmt::format("{}: the propagator at |r| = {:g}, tau = {:g}; its largest value {:.4g} at {:.1f} degrees\n",
                           o.out, o.radius, o.tau, *peak, 360.0 * double(peak - p.begin()) / double(p.size()));
  return 0;
}

void addTextureCommands(CLI::App& app, Commands* commands) {
  auto analyze = std::make_shared<AnalyzeOptions>();
  CLI::App* analyzeCmd =
      app.add_subcommand("analyze", "variogram and regularity REG of an image or field dump (seed 003)");
  analyzeCmd->add_option("file", analyze->file, "PNG/EXR image or DIR/fields/NNNNNN.exr")->required();
  analyzeCmd->add_option("--channel", analyze->channel, "channel (species) to analyse; default the first");
  analyzeCmd
      ->add_option("--max-lag", analyze->maxLag, "largest spacing in cells (default: a quarter of the smaller side)")
      ->check(CLI::Range(1, 1 << 20));
  analyzeCmd->add_flag("--periodic", analyze->periodic, "pairs wrap around (for tiles of periodic runs)");
  analyzeCmd->add_option("--slice", analyze->slice, "z slice of a 3D dump (default: the middle)")
      ->check(CLI::Range(0, 1 << 20));
  analyzeCmd->add_option("--csv", analyze->csv, "also write the variogram per lag and direction");
  analyzeCmd->add_flag("--legibility", analyze->legibility,
                       "instead: a rendered element's median luminance and band-passed contrast (docs/vfx.md)");
  commands->add(analyzeCmd, [analyze] { return analyzeCommand(*analyze); });

  auto plot = std::make_shared<PlotOptions>();
  CLI::App* plotCmd = app.add_subcommand("plot", "plots: `plot propagator SCENE --out FILE.png` (seed 000 fig. 1)");
  plotCmd->add_option("what", plot->what, "propagator")->required();
  plotCmd->add_option("scene", plot->scene, "a scene with [rd.generalized]")->required();
  plotCmd->add_option("--out", plot->out, "the image (.png)")->required();
  plotCmd->add_option("--set", plot->overrides, "key.path=value overrides, as for run");
  plotCmd->add_option("--tau", plot->tau, "the propagator's time")->capture_default_str()->check(finiteIn(1e-3, 1e3));
  plotCmd->add_option("--radius", plot->radius, "|r| of the circle plotted")
      ->capture_default_str()
      ->check(finiteIn(1e-3, 1e3));
  plotCmd->add_option("--size", plot->size, "pixels")->capture_default_str()->check(CLI::Range(64, 8192));
  commands->add(plotCmd, [plot] { return plotCommand(*plot); });

  auto texton = std::make_shared<TextonOptions>();
  TextonWalkSettings& walk = texton->walk;
  CLI::App* textonCmd = app.add_subcommand("texton", "random-walk texton texture (seed 003 eq. 6)");
  textonCmd->add_option("--out", texton->out, "output image (.png or .exr)")->required();
  textonCmd->add_option("--size", walk.width, "field width and height in cells")
      ->capture_default_str()
      ->check(CLI::Range(1, 16384));
  textonCmd->add_option("--elements", walk.elements, "number of textons")
      ->capture_default_str()
      ->check(CLI::Range(1, 10000000));
  textonCmd->add_option("--steps", walk.steps, "random-walk steps")
      ->capture_default_str()
      ->check(CLI::Range(0, 100000000));
  textonCmd->add_option("--step-size", walk.stepSize, "cells per move")
      ->capture_default_str()
      ->check(CLI::Range(1, 16384));
  textonCmd->add_option("--lifetime", walk.lifetime, "mean lifetime L in steps (0: never expire)")
      ->capture_default_str()
      ->check(finiteIn(0.0, 1e9));
  textonCmd->add_option("-p", walk.p, "probability of moving right, given not expired")
      ->capture_default_str()
      ->check(finiteIn(0.0, 1.0));
  textonCmd->add_option("-q", walk.q, "probability of moving left, given not expired")
      ->capture_default_str()
      ->check(finiteIn(0.0, 1.0));
  textonCmd->add_option("--start", texton->start, "pulse | regular | uniform")
      ->check(CLI::IsMember({"pulse", "regular", "uniform"}))
      ->capture_default_str();
  textonCmd->add_option("--radius", walk.radius, "texton disc radius in cells")
      ->capture_default_str()
      ->check(finiteIn(0.0, 16384.0));
  textonCmd->add_option("--seed", walk.seed, "random seed")->capture_default_str();
  textonCmd->add_flag("--analyze", texton->analyze, "also print the texture's REG");
  commands->add(textonCmd, [texton] {
    texton->walk.height = texton->walk.width;
    return textonCommand(*texton);
  });
}

}  // namespace morphoflow
