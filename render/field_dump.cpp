#include "render/field_dump.h"

#include "render/image_file.h"

namespace morphoflow {

namespace {
// Calls fn(cell, pixel) for every grid cell (x fastest) and the index of its
// first channel in the interleaved atlas image: slice z occupies image rows
// z ny .. (z + 1) ny - 1, y up within a slice.
template <typename Fn>
void forEachCellPixel(const std::vector<int>& res, int nc, Fn&& fn) {
  const int nx = res[0], ny = res[1], nz = res.size() > 2 ? res[2] : 1;
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y) {
      const size_t row = size_t(z) * size_t(ny) + size_t(ny - 1 - y);
      for (int x = 0; x < nx; ++x)
        fn((size_t(z) * size_t(ny) + size_t(y)) * size_t(nx) + size_t(x), (row * size_t(nx) + size_t(x)) * size_t(nc));
    }
}
}  // namespace

bool writeFieldDump(const std::string& path, const FieldDump& d, std::string* error) {
  const int nx = d.resolution[0], ny = d.resolution[1], nz = d.resolution.size() > 2 ? d.resolution[2] : 1;
  const int nc = int(d.channels.size());
  OIIO::ImageSpec spec(nx, ny * nz, nc, OIIO::TypeDesc::FLOAT);
  spec.channelnames = d.names;
  spec.alpha_channel = -1;
  spec.attribute("compression", "zip");
  spec.attribute("morphoflow:resolution", OIIO::TypeDesc(OIIO::TypeDesc::INT, int(d.resolution.size())),
                 d.resolution.data());
  spec.attribute("morphoflow:time", float(d.time));
  spec.attribute("morphoflow:step", int(d.step));
  std::vector<float> pixels(size_t(nx) * size_t(ny) * size_t(nz) * size_t(nc));
  forEachCellPixel(d.resolution, nc, [&](size_t cell, size_t px) {
    for (int c = 0; c < nc; ++c) pixels[px + size_t(c)] = d.channels[size_t(c)][cell];
  });
  return writeImageAtomically(path, spec, OIIO::TypeDesc::FLOAT, pixels.data(), error);
}

bool readFieldDump(const std::string& path, FieldDump* d, std::string* error) {
  OIIO::ImageSpec spec;
  std::vector<float> pixels;
  if (!readImageFloat(path, &spec, &pixels, error)) return false;
  const int nc = spec.nchannels;
  d->resolution = {spec.width, spec.height};
  if (const OIIO::ParamValue* r = spec.find_attribute("morphoflow:resolution");
      r && r->type().basetype == OIIO::TypeDesc::INT && (r->type().basevalues() == 2 || r->type().basevalues() == 3)) {
    // OpenEXR keeps int[2] / int[3] as its V2i / V3i vectors: count base values.
    const int* v = static_cast<const int*>(r->data());
    std::vector<int> res(v, v + r->type().basevalues());
    const long cells = long(res[0]) * res[1] * (res.size() > 2 ? res[2] : 1);
    if (res[0] == spec.width && cells == long(spec.width) * spec.height) d->resolution = res;
  }
  d->time = spec.get_float_attribute("morphoflow:time", 0.0f);
  d->step = spec.get_int_attribute("morphoflow:step", 0);
  const int nx = d->resolution[0], ny = d->resolution[1], nz = d->resolution.size() > 2 ? d->resolution[2] : 1;
  d->names.assign(spec.channelnames.begin(), spec.channelnames.end());
  d->names.resize(size_t(nc));
  d->channels.assign(size_t(nc), std::vector<float>(size_t(nx) * size_t(ny) * size_t(nz)));
  forEachCellPixel(d->resolution, nc, [&](size_t cell, size_t px) {
    for (int c = 0; c < nc; ++c) d->channels[size_t(c)][cell] = pixels[px + size_t(c)];
  });
  return true;
}

}  // namespace morphoflow
