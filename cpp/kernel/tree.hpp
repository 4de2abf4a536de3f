// A robot's kinematic tree as the dynamics kernel reads it: flat arrays per body (joint kind and
// axis, parent, indices into q and v, placement, inertia), without Eigen or Pinocchio, so that the
// kernel's units compile in a second and the per-instruction-set units (aba.hpp) share one layout.
//
// Bodies are Pinocchio's joints 1..njoints-1 in Pinocchio's order (a parent before its children);
// body b is joint b + 1. The root body may be a free flyer or a planar joint on the universe; the
// others are revolute (bounded, or unbounded with q = (cos, sin)) or prismatic joints, on an axis
// of their frame (x, y, z, with a sign) or on a general unit axis. Fixed joints never reach here:
// Pinocchio's URDF parser merges them into their parent body (and their frames stay frames).
#pragma once

namespace freefloat::kernel {

// The root joint: none (a fixed base: bodies on the universe are ordinary joints), a free flyer
// (q = [p; quaternion x y z w], v = [v; w] in the root frame) or planar (q = [x, y, cos, sin],
// v = [vx, vy, wz] in the root frame), as Pinocchio's JointModelFreeFlyer and JointModelPlanar.
enum Root : int { kFixed = 0, kFree = 1, kPlanar = 2 };
// A body's joint: revolute (q the angle), revolute unbounded (q = (cos, sin)), prismatic.
enum Kind : int { kRevolute = 0, kUnbounded = 1, kPrismatic = 2 };
// Axis index of a joint along an axis of its frame; kGeneral: along `dir`.
constexpr int kGeneral = 3;

// The tree's arrays (owned by a Kernel, kernel.hpp). Rotations are stored column by column
// (R[3 k + r] is row r of column k) and symmetric 3x3 inertias as (xx, yy, zz, xy, xz, yz).
struct TreeView {
  int nb = 0, nq = 0, nv = 0;
  int root = kFixed;
  bool root_placed = false;    // the root joint's placement in the universe is not the identity
  bool root_armature = false;  // the root joint has armature
  const int *parent, *kind, *axis, *iq, *iv;  // parent body (-1: the universe); indices into q and v
  const double* sign;       // +-1 for an axis of the joint frame
  const double* dir;        // (3,) per body: the unit axis, joint frame (kGeneral)
  const double* rot;        // (9,) per body: the joint frame's axes in the parent's frame
  const double* trans;      // (3,) per body: the joint frame's origin in the parent's frame, m
  const double* armature;   // (nv,) kg m^2 or kg
  double gravity[3] = {0.0, 0.0, 0.0};  // m/s^2, world frame
};

// Four doubles, one state of the tree each, for the lockstep evaluation (GCC's vector extension:
// one AVX2 register in a unit compiled for AVX2, two SSE2 registers otherwise). The baseline ABI
// aligns it to 16 bytes only: kernel.cpp places every array of Lanes at 32 bytes itself.
typedef double Lanes __attribute__((vector_size(32)));

// The bodies' masses and inertias, numbers (T = double) or one per lane (T = Lanes): per body its
// mass (kg), CoM in the joint frame (3,) (m), rotational inertia about the CoM in joint-frame axes
// (6,) (kg m^2).
template <class T>
struct Bodies {
  const T *mass, *com, *inertia;
};

// What one evaluation keeps per body, in world axes at a reference point (the root joint's origin,
// or the world origin on a fixed base): spatial vectors [linear; angular] in Plucker coordinates at
// that point, the articulated inertia as blocks [[A, B], [B^T, C]] (A, C symmetric). T is double,
// or a vector of lanes (aba.hpp) for several states of one tree at once.
template <class T>
struct BodyWork {
  T R[9];        // the body frame's axes in world axes (columns)
  T p[3];        // its origin from the reference point, m
  T S[6];        // motion subspace (one column)
  T v[6];        // spatial velocity
  T c[6];        // velocity-product acceleration v x (S qd)
  T A[6], B[9], C[6];  // articulated inertia (B column by column)
  T f[6];        // articulated bias force
  T U[6];        // articulated inertia times S
  T dinv, u;     // 1 / (S^T U + armature), tau - S^T f
  T a[6];        // spatial acceleration (gravity's opposite included)
};

}  // namespace freefloat::kernel
