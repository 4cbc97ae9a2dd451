// The modes of the compute shaders, one enum a shader: the host chooses a
// mode, and decides anything that depends on it, by value; the #define that
// selects it in the shader's text comes from define() alone.
#pragma once

namespace morphoflow {

// The fluid's stage shaders, one a CPU file (shader() names each mode's)
enum class FluidOp {
  Forces,
  InflowDye,
  Fixed,
  Periodic,
  MacCormack,
  BfeccCorrect,
  BfeccLimit,
  ViscousSetup,
  ViscousStore,
  Divergence,
  WarmStart,
  Gradient,
  ClearPhi
};
// shaders/smoke.comp
enum class SmokeOp { Emit, Inject, Buoyancy, Centre, Vorticity, Confine, AddFaces, Decay };
// shaders/laplace.comp
enum class LaplaceMode { Apply, Residual, Smooth, Jacobi };
// shaders/multigrid.comp's grid transfers
enum class TransferMode { Restrict, Prolong };
// shaders/vector_ops.comp
enum class VectorOp {
  FromFloat, ToFloat, Jacobi, SubMean, UpdateP, UpdateXR, AddFaces, ClampZero, Hold, ScaleAdd, ThetaStep
};
// shaders/rd_lobes.comp and shaders/rd_tensor.comp
enum class LobeMode { A, Faces };
enum class TensorMode { Sigma, Faces };

constexpr const char* define(FluidOp m) {
  switch (m) {
    case FluidOp::Forces: return "MODE_FORCES";
    case FluidOp::InflowDye: return "MODE_INFLOW_DYE";
    case FluidOp::Fixed: return "MODE_FIXED";
    case FluidOp::Periodic: return "MODE_PERIODIC";
    case FluidOp::MacCormack: return "MODE_MACCORMACK";
    case FluidOp::BfeccCorrect: return "MODE_BFECC_CORRECT";
    case FluidOp::BfeccLimit: return "MODE_BFECC_LIMIT";
    case FluidOp::ViscousSetup: return "MODE_VISCOUS_SETUP";
    case FluidOp::ViscousStore: return "MODE_VISCOUS_STORE";
    case FluidOp::Divergence: return "MODE_DIVERGENCE";
    case FluidOp::WarmStart: return "MODE_WARM_START";
    case FluidOp::Gradient: return "MODE_GRADIENT";
    case FluidOp::ClearPhi:
      return "MODE_CLEAR_PHI";
  }
  return "";
}

// The shader of a fluid stage: named after the CPU file of the same stage.
constexpr const char* shader(FluidOp m) {
  switch (m) {
    case FluidOp::Forces:
    case FluidOp::InflowDye:
      return "fluid_forces.comp";
    case FluidOp::Fixed:
    case FluidOp::Periodic:
      return "velocity_constraints.comp";
    case FluidOp::MacCormack:
    case FluidOp::BfeccCorrect:
    case FluidOp::BfeccLimit:
      return "advection_correction.comp";
    case FluidOp::ViscousSetup:
    case FluidOp::ViscousStore:
      return "viscosity.comp";
    case FluidOp::Divergence:
    case FluidOp::WarmStart:
    case FluidOp::Gradient:
    case FluidOp::ClearPhi:
      return "pressure_projection.comp";
  }
  return "";
}

constexpr const char* define(SmokeOp m) {
  switch (m) {
    case SmokeOp::Emit: return "MODE_EMIT";
    case SmokeOp::Inject: return "MODE_INJECT";
    case SmokeOp::Buoyancy: return "MODE_BUOYANCY";
    case SmokeOp::Centre: return "MODE_CENTRE";
    case SmokeOp::Vorticity: return "MODE_VORTICITY";
    case SmokeOp::Confine: return "MODE_CONFINE";
    case SmokeOp::AddFaces: return "MODE_ADD_FACES";
    case SmokeOp::Decay: return "MODE_DECAY";
  }
  return "";
}

constexpr const char* define(LaplaceMode m) {
  switch (m) {
    case LaplaceMode::Apply: return "MODE_APPLY";
    case LaplaceMode::Residual: return "MODE_RESIDUAL";
    case LaplaceMode::Smooth: return "MODE_SMOOTH";
    case LaplaceMode::Jacobi: return "MODE_JACOBI";
  }
  return "";
}

constexpr const char* define(TransferMode m) { return m == TransferMode::Restrict ? "MODE_RESTRICT" : "MODE_PROLONG"; }

constexpr const char* define(VectorOp m) {
  switch (m) {
    case VectorOp::FromFloat: return "OP_FROM_FLOAT";
    case VectorOp::ToFloat: return "OP_TO_FLOAT";
    case VectorOp::Jacobi: return "OP_JACOBI";
    case VectorOp::SubMean: return "OP_SUB_MEAN";
    case VectorOp::UpdateP: return "OP_UPDATE_P";
    case VectorOp::UpdateXR: return "OP_UPDATE_XR";
    case VectorOp::AddFaces: return "OP_ADD_FACES";
    case VectorOp::ClampZero: return "OP_CLAMP_ZERO";
    case VectorOp::Hold: return "OP_HOLD";
    case VectorOp::ScaleAdd: return "OP_SCALE_ADD";
    case VectorOp::ThetaStep: return "OP_THETA_STEP";
  }
  return "";
}

constexpr const char* define(LobeMode m) { return m == LobeMode::A ? "MODE_A" : "MODE_FACES"; }
constexpr const char* define(TensorMode m) { return m == TensorMode::Sigma ? "MODE_SIGMA" : "MODE_FACES"; }

}  // namespace morphoflow
