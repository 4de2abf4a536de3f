// The robot loop's calls to Pinocchio, declared on Pinocchio's forward declarations and Eigen types
// only: the definitions are in pin_plant.cpp, the one translation unit of freefloat.dynamics._sim
// that includes Pinocchio's headers (0.6 GiB and 4 s of a compile by themselves). With the loop's
// own code in one unit they peaked at 1.81 GiB; apart, at 1.15 and 0.85 GiB, so that two compilers
// run at once within 2 GB (setup.py, docs/bench.md "The build").
//
// Every vector is in the order Pinocchio gives it: q (nq,), v and accelerations (nv,), twists and
// wrenches [linear; angular]. A placement is a homogeneous transform (4, 4), as numpy hands it over.
#pragma once

#include <pinocchio/multibody/fwd.hpp>

#include <memory>
#include <vector>

#include "eigen_types.hpp"
#include "model_arrays.hpp"
#include "rkmk.hpp"
#include "wrench_field.hpp"

namespace freefloat::sim {

using Model = pinocchio::Model;
using Matrix6x = Eigen::Matrix<double, 6, Eigen::Dynamic>;

// A Pinocchio Data for one model, without the second-order tensors the loop never computes, and
// the external wrenches per joint (joint frames) that set_wrenches() leaves for aba() and rnea().
struct Workspace;

// Deletes what this header's functions allocate (their types are complete only in pin_plant.cpp).
struct PinDelete {
  void operator()(Model* model) const noexcept;
  void operator()(Workspace* workspace) const noexcept;
};
using ModelPtr = std::unique_ptr<Model, PinDelete>;
using WorkspacePtr = std::unique_ptr<Workspace, PinDelete>;

// The model of `arrays`; std::invalid_argument naming the joint or array at fault.
ModelPtr build_model(const ModelArrays& arrays);
// A workspace for `model` (structure only: any model of the same structure may use it).
WorkspacePtr make_workspace(const Model& model);
WorkspacePtr copy_workspace(const Workspace& workspace);
// Whether a workspace made for `a` serves `b`: the same joints (kind, axis, indices), parents and
// frames' parents. Inertias, placements, armature and gravity may differ: Data holds none of them
// from its construction (the algorithms read them from the model at every call).
bool same_structure(const Model& a, const Model& b);
// `to` takes `from`'s numbers, in place (whoever refers to `to` keeps its address).
void replace(Model& to, ModelPtr from);

int nq(const Model& model);
int nv(const Model& model);
int njoints(const Model& model);
double total_mass(const Model& model);  // kg
Vec3 gravity(const Model& model);       // m/s^2, inertial frame
Vec neutral(const Model& model);        // (nq,)
// The chart blocks of the model's configuration space: its free-flyer and planar joints.
std::vector<ChartBlock> chart_blocks(const Model& model);
// out = q (+) theta (nq,), theta (nv,).
void integrate(const Model& model, const Vec& q, const Vec& theta, Vec& out);
// The chart increment from q0 to q1 (nv,).
Vec difference(const Model& model, const Vec& q0, const Vec& q1);
// The bodies of joints 1..njoints-1 (see Loop::set_bodies): 13 numbers each, mass (kg), CoM in
// the joint frame (3, m), rotational inertia about the CoM in joint-frame axes (3, 3 row-major).
void set_bodies(Model& model, const double* bodies);

// Forward kinematics at q, then the wrenches' inertial [force; torque], the force at the link CoM,
// as joint-frame wrenches for the next aba() and rnea() with `with_wrenches`.
void set_wrenches(const Model& model, Workspace& w, const Vec& q, const std::vector<Wrench>& wrenches);

// ABA: accelerations a (nv,) at (q, v) under generalized forces tau (nv,); Pinocchio's WORLD
// convention when `world`, else LOCAL (the same numbers to round-off).
void aba(const Model& model, Workspace& w, const Vec& q, const Vec& v, const Vec& tau, bool with_wrenches, bool world,
         Vec& a);
// CRBA: the mass matrix M (nv, nv), both triangles; in the WORLD convention the joint Jacobians
// are left as computeJointJacobians leaves them (frame_motion() reads them).
void mass_matrix(const Model& model, Workspace& w, const Vec& q, bool world, Eigen::MatrixXd& M);
// RNEA: the generalized forces (nv,) of the accelerations a at (q, v).
void rnea(const Model& model, Workspace& w, const Vec& q, const Vec& v, const Vec& a, bool with_wrenches, Vec& out);
// The nonlinear effects h = RNEA(q, v, 0) (nv,), without wrenches.
void nonlinear_effects(const Model& model, Workspace& w, const Vec& q, const Vec& v, Vec& h);
// Placements, velocities and accelerations of the joints at (q, v, a).
void forward_kinematics(const Model& model, Workspace& w, const Vec& q, const Vec& v, const Vec& a);

// A frame fixed to a joint, in world axes (closure.FrameMotion), at the joint accelerations
// forward_kinematics() was given.
struct FrameMotion {
  Mat3 rotation;                      // the frame's axes in world axes
  Vec3 position;                      // its origin, world frame (m)
  Vec3 velocity, angular_velocity;    // of its origin (m/s, rad/s)
  Vec3 acceleration;                  // classical acceleration of its origin (m/s^2)
  Vec3 angular_acceleration;          // rad/s^2
  Matrix6x jacobian;                  // [linear; angular] (6, nv) at its origin (LOCAL_WORLD_ALIGNED)
};

// The frame `placement` (4, 4) on `joint` after forward_kinematics() and the joint Jacobians.
void frame_motion(const Model& model, Workspace& w, int joint, const Pose& placement, FrameMotion& out);

// A frame's orientation (its axes in world axes) and origin (world frame, m).
struct FramePose {
  Mat3 rotation;
  Vec3 position;
};
// The frame `placement` (4, 4) on `joint`, after forward kinematics.
FramePose frame_pose(const Workspace& w, int joint, const Pose& placement);
// The rotation vector of R (3, 3): pinocchio::log3.
Vec3 log3(const Mat3& R);

// A telemetry row's quantities at (q, v), world frame.
struct Snapshot {
  Vec6 momentum;               // [P; L], L about the world origin (kg m/s, kg m^2/s)
  Vec6 base_twist;             // [v; w] of the base frame's origin, world axes (LOCAL_WORLD_ALIGNED)
  Vec3 com, base_position;     // system CoM and base frame origin (m)
  Mat3 base_rotation;          // base frame axes in world axes
  double kinetic_energy = 0.0; // J
  std::vector<Vec3> ee_position;  // end-effector frame origins (m), in ee_frames' order
  std::vector<Mat3> ee_rotation;  // their axes in world axes
};
void snapshot(const Model& model, Workspace& w, const Vec& q, const Vec& v, int base_frame,
              const std::vector<int>& ee_frames, Snapshot& out);

// What generalized_jacobian() (generalized_jacobian.hpp) takes from Pinocchio at (q, v): from the
// centroidal momentum matrix (ccrba), the columns [H0m | M] (6, n + 1), [P; L about the base CoM]
// of unit joint rates at a still base link, then of the state; H0 (6, 6), the locked robot's
// spatial inertia about the base CoM (eq 23); the base CoM position r0; per end-effector frame its
// origin r_E and Jacobian [v_E; w_E] (6, nv), world axes. The base is treated as a free rigid body
// in 3-D whatever the root joint (a planar root is embedded in 3-D, as in gjm.compute).
struct CentroidalFrames {
  Eigen::MatrixXd momentum;
  Eigen::Matrix<double, 6, 6> H0;
  Vec3 base_position;
  std::vector<Vec3> ee_position;
  std::vector<Matrix6x> ee_jacobian;
};
// `base_frame` is the base CoM frame, `ee_frames` the end-effector frames, n the actuated joints
// (the last n velocities).
void centroidal_frames(const Model& model, Workspace& w, const Vec& q, const Vec& v, int base_frame,
                       const std::vector<int>& ee_frames, int n, CentroidalFrames& out);

}  // namespace freefloat::sim
