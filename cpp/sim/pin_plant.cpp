// The definitions of sim/pin_plant.hpp: the robot loop's calls to Pinocchio, in the one translation
// unit of freefloat.dynamics._sim that includes Pinocchio's headers (setup.py compiles it at -O1:
// its time is in libpinocchio_default's algorithms).
#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/center-of-mass.hpp>
#include <pinocchio/algorithm/centroidal.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/energy.hpp>
#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/jacobian.hpp>
#include <pinocchio/algorithm/joint-configuration.hpp>
#include <pinocchio/algorithm/kinematics.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/multibody.hpp>
#include <pinocchio/spatial.hpp>

#include <stdexcept>
#include <string>
#include <utility>

#include "pin_plant.hpp"

namespace freefloat::sim {

using pinocchio::Data;
using pinocchio::Force;
using pinocchio::Inertia;
using pinocchio::JointIndex;
using pinocchio::JointModel;
using pinocchio::SE3;

// The pin wheel's libpinocchio_default holds Pinocchio's algorithms compiled for double, the
// default joints and Eigen::Ref<const VectorXd> arguments (explicit instantiation); this module is
// built with PINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION and linked to it, so that a call with these
// argument types uses that code instead of instantiating the algorithm here (instantiating aba,
// crba, ccrba, ... was most of the build's time and memory). Most algorithms convert their vector
// arguments to ConstRef themselves; aba and crba take ConstRef arguments from the caller.
using ConstRef = Eigen::Ref<const Vec>;

struct Workspace {
  Data data;
  std::vector<Force> fext;  // per joint, joint frame
};

void PinDelete::operator()(Model* model) const noexcept { delete model; }
void PinDelete::operator()(Workspace* workspace) const noexcept { delete workspace; }

namespace {

// The joint of Pinocchio kind `kind` whose motion subspace is `S` = [linear; angular] (6,), for
// the 1-dof kinds; the root kinds take no axis.
JointModel make_joint(const std::string& kind, const Vec6& S, const std::string& name) {
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
SE3 se3_of(const Pose& H) { return SE3(Mat3(H.topLeftCorner<3, 3>()), Vec3(H.topRightCorner<3, 1>())); }
SE3 se3_at(const double* p) { return se3_of(Eigen::Map<const Pose>(p)); }

}  // namespace

ModelPtr build_model(const ModelArrays& a) {
  if (a.kind.size() != a.parent.size() || a.name.size() != a.parent.size())
    throw std::invalid_argument("parent, kind, name: expected one entry per joint");
  ModelPtr out(new Model);
  Model& m = *out;
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
  return out;
}

// Data's constructor allocates the kinematic Hessians (6 x nv x nv) and the four nv x nv x nv
// d2tau tensors (about 250 MB at nv 198): released at once, so that a copy costs O(nv^2).
WorkspacePtr make_workspace(const Model& model) {
  WorkspacePtr w(new Workspace{Data(model), std::vector<Force>(model.njoints, Force::Zero())});
  Data& d = w->data;
  d.kinematic_hessians.resize(0, 0, 0);
  d.d2tau_dqdq.resize(0, 0, 0);
  d.d2tau_dvdv.resize(0, 0, 0);
  d.d2tau_dqdv.resize(0, 0, 0);
  d.d2tau_dadq.resize(0, 0, 0);
  return w;
}

WorkspacePtr copy_workspace(const Workspace& workspace) { return WorkspacePtr(new Workspace(workspace)); }

bool same_structure(const Model& a, const Model& b) {
  if (a.njoints != b.njoints || a.nq != b.nq || a.nv != b.nv || a.nframes != b.nframes) return false;
  for (JointIndex j = 0; j < static_cast<JointIndex>(a.njoints); ++j)
    if (a.parents[j] != b.parents[j] || !(a.joints[j] == b.joints[j])) return false;
  for (size_t f = 0; f < a.frames.size(); ++f)
    if (a.frames[f].parentJoint != b.frames[f].parentJoint) return false;
  return true;
}

void replace(Model& to, ModelPtr from) { to = std::move(*from); }

int nq(const Model& model) { return model.nq; }
int nv(const Model& model) { return model.nv; }
int njoints(const Model& model) { return model.njoints; }
double total_mass(const Model& model) { return pinocchio::computeTotalMass(model); }
Vec3 gravity(const Model& model) { return model.gravity.linear(); }
Vec neutral(const Model& model) { return pinocchio::neutral(model); }

std::vector<ChartBlock> chart_blocks(const Model& model) {
  std::vector<ChartBlock> blocks;
  for (JointIndex j = 1; j < model.joints.size(); ++j) {
    const std::string kind = model.joints[j].shortname();
    if (kind == "JointModelFreeFlyer") blocks.push_back({model.joints[j].idx_v(), 6});
    if (kind == "JointModelPlanar") blocks.push_back({model.joints[j].idx_v(), 3});
  }
  return blocks;
}

void integrate(const Model& model, const Vec& q, const Vec& theta, Vec& out) { pinocchio::integrate(model, q, theta, out); }
Vec difference(const Model& model, const Vec& q0, const Vec& q1) { return pinocchio::difference(model, q0, q1); }

// With build_model's very operations (the body appended to a zero inertia, then each frame's
// inertia, zero, appended as addFrame does): a model equal to the rebuilt one bit for bit.
void set_bodies(Model& model, const double* bodies) {
  for (JointIndex j = 1; j < static_cast<JointIndex>(model.njoints); ++j, bodies += 13) {
    const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> I(bodies + 4);
    model.inertias[j] = Inertia::Zero();
    model.inertias[j] += Inertia(bodies[0], Eigen::Map<const Vec3>(bodies + 1), Mat3(I)).se3Action(SE3::Identity());
  }
  for (const pinocchio::Frame& frame : model.frames)
    if (frame.parentJoint > 0) model.inertias[frame.parentJoint] += frame.placement.act(frame.inertia);
}

void set_wrenches(const Model& model, Workspace& w, const Vec& q, const std::vector<Wrench>& wrenches) {
  pinocchio::forwardKinematics(model, w.data, q);
  for (Force& f : w.fext) f.setZero();
  for (const Wrench& x : wrenches) {  // WrenchProfiles.forces: inertial [f; n] at the link CoM
    const Mat3& R = w.data.oMi[x.joint].rotation();
    const Vec3 f = R.transpose() * x.force;
    w.fext[x.joint] += Force(f, R.transpose() * x.torque + x.com.cross(f));
  }
}

void aba(const Model& model, Workspace& w, const Vec& q, const Vec& v, const Vec& tau, bool with_wrenches, bool world,
         Vec& a) {
  const pinocchio::Convention convention = world ? pinocchio::Convention::WORLD : pinocchio::Convention::LOCAL;
  if (with_wrenches)
    a = pinocchio::aba(model, w.data, ConstRef(q), ConstRef(v), ConstRef(tau), w.fext, convention);
  else
    a = pinocchio::aba(model, w.data, ConstRef(q), ConstRef(v), ConstRef(tau), convention);
}

void mass_matrix(const Model& model, Workspace& w, const Vec& q, bool world, Eigen::MatrixXd& M) {
  const pinocchio::Convention convention = world ? pinocchio::Convention::WORLD : pinocchio::Convention::LOCAL;
  M = pinocchio::crba(model, w.data, ConstRef(q), convention).selfadjointView<Eigen::Upper>();
}

void rnea(const Model& model, Workspace& w, const Vec& q, const Vec& v, const Vec& a, bool with_wrenches, Vec& out) {
  if (with_wrenches)
    out = pinocchio::rnea(model, w.data, ConstRef(q), ConstRef(v), ConstRef(a), w.fext);
  else
    out = pinocchio::rnea(model, w.data, ConstRef(q), ConstRef(v), ConstRef(a));
}

void nonlinear_effects(const Model& model, Workspace& w, const Vec& q, const Vec& v, Vec& h) {
  h = pinocchio::nonLinearEffects(model, w.data, q, v);
}

void forward_kinematics(const Model& model, Workspace& w, const Vec& q, const Vec& v, const Vec& a) {
  pinocchio::forwardKinematics(model, w.data, ConstRef(q), ConstRef(v), ConstRef(a));
}

void frame_motion(const Model& model, Workspace& w, int joint, const Pose& placement_h, FrameMotion& out) {
  const Data& d = w.data;
  const SE3 placement = se3_of(placement_h), pose = d.oMi[joint] * placement;
  out.rotation = pose.rotation();
  out.position = pose.translation();
  const Mat3& R = out.rotation;
  const pinocchio::Motion velocity = placement.actInv(d.v[joint]), acc = placement.actInv(d.a[joint]);
  out.velocity = R * velocity.linear();
  out.angular_velocity = R * velocity.angular();
  out.acceleration = R * (acc.linear() + velocity.angular().cross(velocity.linear()));
  out.angular_acceleration = R * acc.angular();
  out.jacobian.setZero(6, model.nv);
  pinocchio::getFrameJacobian(model, w.data, static_cast<JointIndex>(joint), placement, pinocchio::LOCAL_WORLD_ALIGNED,
                              out.jacobian);
}

FramePose frame_pose(const Workspace& w, int joint, const Pose& placement) {
  const SE3 pose = w.data.oMi[joint] * se3_of(placement);
  return {pose.rotation(), pose.translation()};
}

Vec3 log3(const Mat3& R) { return pinocchio::log3(R); }

void snapshot(const Model& model, Workspace& w, const Vec& q, const Vec& v, int base_frame,
              const std::vector<int>& ee_frames, Snapshot& out) {
  Data& d = w.data;
  const Force& hg = pinocchio::computeCentroidalMomentum(model, d, q, v);
  out.com = d.com[0];
  out.momentum.head<3>() = hg.linear();
  out.momentum.tail<3>() = hg.angular() + out.com.cross(hg.linear());
  out.kinetic_energy = pinocchio::computeKineticEnergy(model, d);
  const SE3& base = pinocchio::updateFramePlacement(model, d, base_frame);
  out.base_position = base.translation();
  out.base_rotation = base.rotation();
  out.base_twist = pinocchio::getFrameVelocity(model, d, base_frame, pinocchio::LOCAL_WORLD_ALIGNED).toVector();
  const size_t ne = ee_frames.size();
  out.ee_position.resize(ne);
  out.ee_rotation.resize(ne);
  for (size_t e = 0; e < ne; ++e) {
    const SE3& frame = pinocchio::updateFramePlacement(model, d, ee_frames[e]);
    out.ee_position[e] = frame.translation();
    out.ee_rotation[e] = frame.rotation();
  }
}

void centroidal_frames(const Model& m, Workspace& w, const Vec& q, const Vec& v, int base_frame,
                       const std::vector<int>& ee_frames, int n, CentroidalFrames& out) {
  Data& d = w.data;
  pinocchio::ccrba(m, d, q, v);  // Ag, hg about the CoM (inertial axes), Ig, com
  pinocchio::computeJointJacobians(m, d, q);
  out.base_position = pinocchio::updateFramePlacement(m, d, base_frame).translation();
  const Vec3 c = d.com[0] - out.base_position;  // system CoM from the base CoM
  out.momentum.resize(6, n + 1);
  out.momentum.leftCols(n) = d.Ag.rightCols(n);
  out.momentum.col(n) = d.hg.toVector();
  for (int j = 0; j <= n; ++j) out.momentum.col(j).tail<3>() += c.cross(Vec3(out.momentum.col(j).head<3>()));
  out.H0 = Inertia(d.Ig.mass(), c, d.Ig.inertia()).matrix();
  const size_t k = ee_frames.size();
  out.ee_position.resize(k);
  out.ee_jacobian.resize(k);
  for (size_t e = 0; e < k; ++e) {
    out.ee_position[e] = pinocchio::updateFramePlacement(m, d, ee_frames[e]).translation();
    out.ee_jacobian[e].setZero(6, m.nv);
    pinocchio::getFrameJacobian(m, d, ee_frames[e], pinocchio::LOCAL_WORLD_ALIGNED, out.ee_jacobian[e]);
  }
}

// Declared in simulation.hpp, which the loop's bindings include without Pinocchio's headers.
const char* pinocchio_version() { return PINOCCHIO_VERSION; }

}  // namespace freefloat::sim
