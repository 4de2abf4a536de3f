// A pinocchio::Model rebuilt in C++ from the arrays that describe a Python-side pin.Model (no
// object is shared across the two bindings): joints with their kind, parent, placement and
// motion subspace, the joint inertias (fixed links already merged), armature, gravity, frames.
#pragma once

#include <pinocchio/multibody.hpp>

#include <stdexcept>
#include <string>
#include <vector>

#include "eigen_types.hpp"
#include "model_arrays.hpp"

namespace freefloat::sim {

using pinocchio::Data;
using pinocchio::Inertia;
using pinocchio::JointIndex;
using pinocchio::JointModel;
using pinocchio::Model;
using pinocchio::SE3;

// The pin wheel's libpinocchio_default holds Pinocchio's algorithms compiled for double, the
// default joints and Eigen::Ref<const VectorXd> arguments (explicit instantiation); this module is
// built with PINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION and linked to it, so that a call with these
// argument types uses that code instead of instantiating the algorithm here (instantiating aba,
// crba, ccrba, ... was most of the build's time and memory). Most algorithms convert their vector
// arguments to ConstRef themselves; aba and crba take ConstRef arguments from the caller.
using ConstRef = Eigen::Ref<const Vec>;

// The joint of Pinocchio kind `kind` whose motion subspace is `S` = [linear; angular] (6,), for
// the 1-dof kinds; the root kinds take no axis.
inline JointModel make_joint(const std::string& kind, const Vec6& S, const std::string& name) {
  using namespace pinocchio;
  const Vec3 lin = S.head<3>(), ang = S.tail<3>();
  if (kind == "JointModelFreeFlyer") return JointModelFreeFlyer();
  if (kind == "JointModelPlanar") return JointModelPlanar();
  if (kind == "JointModelRX") return JointModelRX();
  if (kind == "JointModelRY") return JointModelRY();
  if (kind == "JointModelRZ") return JointModelRZ();
  if (kind == "JointModelRUBX") return JointModelRUBX();
  if (kind == "JointModelRUBY") return JointModelRUBY();
  if (kind == "JointModelRUBZ") return JointModelRUBZ();
  if (kind == "JointModelPX") return JointModelPX();
  if (kind == "JointModelPY") return JointModelPY();
  if (kind == "JointModelPZ") return JointModelPZ();
  if (kind == "JointModelRevoluteUnaligned") return JointModelRevoluteUnaligned(ang.normalized());
  if (kind == "JointModelRevoluteUnboundedUnaligned") return JointModelRevoluteUnboundedUnaligned(ang.normalized());
  if (kind == "JointModelPrismaticUnaligned") return JointModelPrismaticUnaligned(lin.normalized());
  throw std::invalid_argument("joint '" + name + "': kind " + kind + " is not supported by the compiled simulation");
}

// The placement of the homogeneous transform H (4, 4).
inline SE3 se3_of(const Pose& H) { return SE3(Mat3(H.topLeftCorner<3, 3>()), Vec3(H.topRightCorner<3, 1>())); }
inline SE3 se3_at(const double* p) { return se3_of(Eigen::Map<const Pose>(p)); }

// A Data for `model` without Pinocchio's second-order tensors (kinematic Hessians 6 x nv x nv and
// the four nv x nv x nv d2tau tensors, about 250 MB at nv 198): the loop computes no second-order
// derivative, so they are allocated once by Data's constructor and released at once. A copy of
// the result costs O(nv^2), so a loop's second Data is a copy of its first.
inline Data lean_data(const Model& model) {
  Data d(model);
  d.kinematic_hessians.resize(0, 0, 0);
  d.d2tau_dqdq.resize(0, 0, 0);
  d.d2tau_dvdv.resize(0, 0, 0);
  d.d2tau_dqdv.resize(0, 0, 0);
  d.d2tau_dadq.resize(0, 0, 0);
  return d;
}

// Whether a Data made for `a` serves `b`: the same joints (kind, axis, indices), parents and
// frames' parents. Inertias, placements, armature and gravity may differ: Data holds none of
// them from its construction (the algorithms read them from the model at every call).
inline bool same_structure(const Model& a, const Model& b) {
  if (a.njoints != b.njoints || a.nq != b.nq || a.nv != b.nv || a.nframes != b.nframes) return false;
  for (JointIndex j = 0; j < static_cast<JointIndex>(a.njoints); ++j)
    if (a.parents[j] != b.parents[j] || !(a.joints[j] == b.joints[j])) return false;
  for (size_t f = 0; f < a.frames.size(); ++f)
    if (a.frames[f].parentJoint != b.frames[f].parentJoint) return false;
  return true;
}

// The model of `a`; std::invalid_argument naming the joint or array at fault.
inline Model build_model(const ModelArrays& a) {
  if (a.kind.size() != a.parent.size() || a.name.size() != a.parent.size())
    throw std::invalid_argument("parent, kind, name: expected one entry per joint");
  Model m;
  const size_t n = a.parent.size();
  for (size_t j = 0; j < n; ++j) {
    const int parent = a.parent[j];
    if (parent < 0 || parent > static_cast<int>(j))
      throw std::invalid_argument("joint '" + a.name[j] + "': its parent must come before it");
    const JointIndex id = m.addJoint(static_cast<JointIndex>(parent),
                                     make_joint(a.kind[j], Eigen::Map<const Vec6>(a.subspace + 6 * j), a.name[j]),
                                     se3_at(a.placement + 16 * j), a.name[j]);
    Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> I(a.rotational + 9 * j);
    m.appendBodyToJoint(id, Inertia(a.mass[j], Eigen::Map<const Vec3>(a.lever + 3 * j), Mat3(I)), SE3::Identity());
  }
  if (a.armature_size != m.nv) throw std::invalid_argument("armature: expected one entry per velocity");
  m.armature = Eigen::Map<const Vec>(a.armature, m.nv);
  m.gravity.linear(Eigen::Map<const Vec3>(a.gravity));
  for (size_t f = 0; f < a.frame_parent.size(); ++f)
    m.addFrame(pinocchio::Frame("frame" + std::to_string(f), static_cast<JointIndex>(a.frame_parent[f]),
                                se3_at(a.frame_placement + 16 * f), pinocchio::OP_FRAME));
  return m;
}

}  // namespace freefloat::sim
