// [[obstacles]]: circles, spheres, boxes and image or signed-distance shapes.
#include <algorithm>
#include <cmath>
#include <filesystem>

#include <fmt/format.h>

#include "fluid/obstacle_motion.h"
#include "render/image_io.h"
#include "scenes/scene_reader.h"

namespace morphoflow {

ObstacleShape parseShape(const std::string& s) {
  if (s == "circle") return ObstacleShape::Circle;
  if (s == "sphere") return ObstacleShape::Sphere;
  if (s == "box") return ObstacleShape::Box;
  if (s == "image") return ObstacleShape::Image;
  return ObstacleShape::Sdf;
}

// A shape (obstacles' and sources' alike) from the table o whose keys are
// prefixed p: shape, center (inside the domain), radius, size or file.
ObstacleSpec parseRegion(SceneContext& c, const toml::table* o, const std::string& p) {
  Reader& r = c.r;
  const int D = c.D;
  const std::vector<double>& size = c.size;
  ObstacleSpec spec;
  std::string shape = r.string(o, p, "shape", "circle", {"circle", "sphere", "box", "image", "sdf"});
  spec.shape = parseShape(shape);
  std::vector<double> centre(static_cast<size_t>(D), 0.0);
  for (int a = 0; a < D; ++a) centre[size_t(a)] = 0.5 * size[size_t(a)];
  const toml::node* cn = nullptr;
  centre = r.numbers(o, p, "center", centre, size_t(D), size_t(D), -1e9, 1e9, false, &cn);
  for (int a = 0; a < D; ++a) {
    if (centre[size_t(a)] < 0 || centre[size_t(a)] > size[size_t(a)])
      r.fail(cn, p + "center", "the centre lies outside the domain",
             fmt::format("domain.size is {:g} along axis {}", size[size_t(a)], a));
    spec.center[size_t(a)] = centre[size_t(a)];
  }
  if (spec.shape == ObstacleShape::Circle || spec.shape == ObstacleShape::Sphere) {
    if (!r.node(o, p, "radius")) r.fail(o, p + "radius", "a " + shape + " needs a radius");
    spec.radius = r.number(o, p, "radius", 0.1, 0, 1e9, true);
  } else if (spec.shape == ObstacleShape::Box) {
    if (!r.node(o, p, "size")) r.fail(o, p + "size", "a box needs a size = [..] (its full extent)");
    std::vector<double> sz = r.numbers(o, p, "size", {}, size_t(D), size_t(D), 0, 1e9, true);
    for (int a = 0; a < D; ++a) spec.halfSize[size_t(a)] = 0.5 * sz[size_t(a)];
  } else {
    // The image (or sdf) is stretched over the domain: a centre would move nothing.
    if (cn)
      r.fail(cn, p + "center",
             "an " + shape + " region is its file stretched over the whole domain: a center does not apply",
             "remove center, and draw the shape where it goes in the " + shape);
    const std::string key = "file";
    const toml::node* fn = r.node(o, p, key);
    if (!fn) r.fail(o, p + key, "an " + shape + " region needs file = \"path\"");
    std::string file = r.string(o, p, key, "");
    std::filesystem::path fp =
        std::filesystem::path(file).is_absolute() ? std::filesystem::path(file) : c.sceneDir / file;
    GrayImage img;
    std::string err;
    if (!readGrayImage(fp.string(), &img, &err)) r.fail(fn, p + key, "cannot read the image: " + err);
    r.noteInput(fp, fn, p + key);
    // One rule for every sdf: a distance is finite (an infinite or NaN one
    // would be read as no solid, where a finite negative one is solid).
    for (size_t i = 0; i < img.pixels.size() && spec.shape == ObstacleShape::Sdf; ++i)
      if (!std::isfinite(img.pixels[i]))
        r.fail(fn, p + key,
               fmt::format("the sdf holds {} at pixel ({}, {}): a signed distance is a finite number", img.pixels[i],
                           i % size_t(img.width), i / size_t(img.width)),
               "write finite distances (negative inside), or use shape = \"image\" with a threshold");
    spec.fieldWidth = img.width;
    spec.fieldHeight = img.height;
    spec.field = std::move(img.pixels);
    spec.threshold = r.number(o, p, "threshold", 0.5, -1e9, 1e9);
    spec.invert = r.boolean(o, p, "invert", false);
  }
  return spec;
}

// An array of tables ([[name]]) at the root, or none.
const toml::array* tableArray(Reader& r, toml::table& root, const std::string& name) {
  const toml::table* top = &root;
  r.node(top, "", name);
  const toml::node* n = root.get(name);
  if (!n) return nullptr;
  const toml::array* arr = n->as_array();
  if (!arr || !arr->is_array_of_tables()) r.fail(n, name, "expected an array of tables ([[" + name + "]])");
  return arr;
}

namespace {

// obstacles.N.motion (the centre per axis) or obstacles.N.rotation (2D: one
// angle; 3D: three), expressions in t.
std::vector<std::string> parseKinematics(SceneContext& c, const toml::table* o, const std::string& p,
                                         const std::string& key, size_t count, const std::string& example) {
  Reader& r = c.r;
  const toml::node* n = r.node(o, p, key);
  if (!n) return {};
  const toml::array* arr = n->as_array();
  if (!arr || arr->size() != count)
    r.fail(n, p + key, fmt::format("expected {} expressions in t", count), "e.g. " + key + " = " + example);
  return expressionList(r, *arr, p + key, {"t"}, key, "the variable is t");
}

// A moving obstacle's motion over its window (to the run's end): finite,
// and no point of it moving farther in one step than its own half
// thickness (else it would pass through the fluid it should push aside).
void checkMotion(SceneContext& c, const Scene& s, const ObstacleSpec& spec, const TimeWindow& w, const toml::table* o,
                 const std::string& p) {
  Reader& r = c.r;
  const TimeSettings& ts = s.time;
  double end = ts.steps > 0 ? double(ts.steps) * ts.dt : ts.duration > 0 ? ts.duration : TimeSettings::kSteadyCap;
  end = std::min(end, w.end);
  const double h = c.size[0] / c.res[0];
  double thickness = spec.radius;
  if (spec.shape == ObstacleShape::Box) {
    thickness = spec.halfSize[0];
    for (int a = 1; a < c.D; ++a) thickness = std::min(thickness, spec.halfSize[size_t(a)]);
  }
  const long samples = std::clamp(long(std::ceil((end - w.start) / ts.dt)), 1L, 100000L);
  const std::string key = spec.motion.empty() ? "rotation" : "motion";
  for (long k = 0; k <= samples; ++k) {
    const double t = w.start + (end - w.start) * double(k) / double(samples);
    RigidMotion m;
    const ObstacleSpec at = placedAt(spec, c.D, t, &m);
    bool finite = true;
    for (int a = 0; a < 3; ++a)
      finite = finite && std::isfinite(at.center[size_t(a)]) && std::isfinite(m.velocity[size_t(a)]) &&
               std::isfinite(m.omega[size_t(a)]);
    for (double v : at.orientation) finite = finite && std::isfinite(v);
    if (!finite)
      r.fail(r.node(o, p, key), p + key,
             fmt::format("the {} is not finite at t = {:g} (its centre, angle or their rate)", key, t),
             "give expressions finite over the obstacle's window (start to end, or to the run's end)");
    const double speed = obstacleSpeedBound(spec, c.D, t);
    const double dt = ts.cfl > 0 && speed > 0 ? std::min(ts.dt, ts.cfl * h / speed) : ts.dt;
    if (speed * dt > thickness)
      r.fail(r.node(o, p, key), p + key,
             fmt::format("at t = {:g} a point of the obstacle moves {:g} in one step of {:g}, more than its half "
                         "thickness {:g}: it would pass through the fluid it should push",
                         t, speed * dt, dt, thickness),
             "use a smaller time.dt, set time.cfl, or slow the motion");
  }
}

}  // namespace

void parseObstacles(SceneContext& c, Scene* s) {
  if (const toml::array* arr = tableArray(c.r, c.root, "obstacles"))
    for (size_t i = 0; i < arr->size(); ++i) {
      const toml::table* o = arr->get(i)->as_table();
      const std::string p = "obstacles." + std::to_string(i) + ".";
      Reader& r = c.r;
      // An image or sdf is its file stretched over the domain: no centre to move or turn about.
      const std::string shape = r.string(o, p, "shape", "circle", {"circle", "sphere", "box", "image", "sdf"});
      for (const char* key : {"motion", "rotation"})
        if ((shape == "image" || shape == "sdf") && r.node(o, p, key))
          r.fail(r.node(o, p, key), p + key,
                 fmt::format("an {} obstacle is its file stretched over the whole domain: it has no centre to {}",
                             shape, key == std::string("motion") ? "move" : "turn about"),
                 "remove " + std::string(key) + ", or give the obstacle a circle, sphere or box shape");
      ObstacleSpec spec = parseRegion(c, o, p);
      // Where the fluid meets it: its own surface (cut cells) or its cells' staircase.
      spec.boundary = c.r.string(o, p, "boundary", "cut", {"cut", "voxel"}) == "voxel" ? ObstacleBoundary::Voxel
                                                                                       : ObstacleBoundary::Cut;
      spec.motion =
          parseKinematics(c, o, p, "motion", size_t(c.D),
                          c.D == 2 ? "[\"0.5 + 0.2 * t\", \"0.5\"]" : "[\"0.5 + 0.2 * t\", \"0.5\", \"0.5\"]");
      spec.rotation = parseKinematics(c, o, p, "rotation", c.D == 2 ? 1 : 3,
                                      c.D == 2 ? "[\"2 * t\"]" : "[\"0\", \"0\", \"2 * t\"]");
      if (!spec.motion.empty() && r.node(o, p, "center"))
        r.fail(r.node(o, p, "center"), p + "center", "the motion gives the centre at every time: center does not apply",
               "remove center, and start the motion where the obstacle starts");
      const TimeWindow window = parseWindow(c.r, o, p);
      if (movesAtAll(spec)) checkMotion(c, *s, spec, window, o, p);
      s->fluid.obstacles.push_back(std::move(spec));
      s->timeline.obstacles.push_back(window);
    }
}

}  // namespace morphoflow
