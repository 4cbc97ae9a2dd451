#include "sim/scene_inputs.h"

#include <array>

#include "core/error.h"
#include "coupling/given_velocity.h"

namespace morphoflow {

namespace {

template <int D>
void readFirstFrame(const Scene& s) {
  std::array<double, D> domain{};
  IVec<D> cells;
  std::array<bool, D> periodic{};
  for (int a = 0; a < D; ++a) {
    domain[size_t(a)] = s.rd.settings.size[size_t(a)];
    cells[a] = s.rd.settings.resolution[size_t(a)];
  }
  const std::vector<VelocityFrame> frames = findVelocityFrames(s.velocity.vdb, s.velocity.frameTime);
  VdbVelocitySequence<D> seq({frames.front()}, domain);
  MacVelocity<D> u(cells, domain[0] / cells[0], periodic);
  seq.sample(frames.front().time, &u);
}

}  // namespace

void checkSceneInputs(const Scene& s) {
  if (!s.velocity.enabled || s.velocity.vdb.empty()) return;
  try {
    if (s.dimension == 2) readFirstFrame<2>(s);
    else readFirstFrame<3>(s);
  } catch (const VelocityFileError& e) {
    throw UserError(s.velocity.where, s.velocity.key, e.path() + ": " + e.what(), kVelocityFilesHint);
  }
}

}  // namespace morphoflow
