// freefloat's dynamics kernel: the articulated-body algorithm (kernel/aba.hpp) specialised at
// load time to one robot's tree (kernel/tree.hpp), for one state or for kLanes states of the tree
// at once. It takes the arrays the compiled loop rebuilds Pinocchio's model from (ModelArrays) and
// needs no Pinocchio header; Pinocchio stays the reference it is tested against.
//
// Vectors are in Pinocchio's order: q (nq,), v, tau and accelerations (nv,); a free root's
// velocity and acceleration [linear; angular] in its own frame.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "tree.hpp"
#include "wrench.hpp"

namespace freefloat::sim {
struct ModelArrays;
}

namespace freefloat::kernel {

class Kernel {
 public:
  static constexpr int kLanes = 4;  // states of one lockstep evaluation

  // The kernel of `arrays`' tree, or null when it has a joint the kernel does not have (`why`, if
  // given, says which): a free flyer or planar joint that is not the root, or any other kind.
  static std::unique_ptr<Kernel> build(const sim::ModelArrays& arrays, std::string* why = nullptr);
  ~Kernel();
  // A kernel of the same tree, numbers and lanes' bodies, with a workspace of its own.
  std::unique_ptr<Kernel> clone() const;

  int nq() const { return tree_.nq; }
  int nv() const { return tree_.nv; }
  // The root joint (tree.hpp's Root).
  int root() const { return tree_.root; }

  // The numbers of `arrays` (inertias, placements, armature, gravity), a model of this tree's
  // structure: std::invalid_argument otherwise.
  void set_numbers(const sim::ModelArrays& arrays);
  // The bodies of joints 1..njoints-1, 13 numbers each: mass (kg), CoM in the joint frame (3, m),
  // rotational inertia about the CoM in joint-frame axes (3, 3 row-major, kg m^2).
  void set_bodies(const double* bodies);
  // The bodies of lane `lane` of the lockstep evaluation only (as set_bodies'), until the next
  // set_bodies() or set_numbers().
  void set_lane_bodies(int lane, const double* bodies);

  // a (nv,) = the accelerations at (q, v) under generalized forces tau and the wrenches.
  void aba(const double* q, const double* v, const double* tau, const Wrenches& wrenches, double* a);
  // The same for kLanes states at once: q[l], v[l], tau[l], wrenches[l] (null: none) -> a[l].
  void aba_lanes(const double* const* q, const double* const* v, const double* const* tau, const Wrenches* wrenches,
                 double* const* a);

  // The instruction set the evaluations use: "avx2" (on a CPU that has it) or
  // "baseline" (the platform's, e.g. SSE2 on x86-64). set_isa("baseline") makes every kernel of
  // the process take the baseline code (tests and benchmarks compare the two); "avx2" undoes it.
  static const char* isa();
  static void set_isa(const std::string& name);

 private:
  Kernel() = default;
  void allocate();  // the workspaces, for tree_'s sizes
  void read(const sim::ModelArrays& arrays);
  void copy_lane_bodies(int lane);  // lane `lane`'s bodies from the tree's
  TreeView view() const;

  TreeView tree_;
  std::vector<int> parent_, kind_, axis_, iq_, iv_;
  std::vector<double> sign_, dir_, rot_, trans_, armature_;  // the TreeView's arrays
  std::vector<double> mass_, com_, inertia_;                  // the bodies' (Bodies<double>)
  std::vector<BodyWork<double>> work_;
  // The lockstep workspace and states in structure-of-arrays order (kLanes numbers per entry), in
  // one buffer aligned to 32 bytes (a container of Lanes would not be in a unit without AVX).
  std::vector<double> lane_buffer_;
  BodyWork<Lanes>* lane_work_ = nullptr;
  Lanes *lane_q_ = nullptr, *lane_v_ = nullptr, *lane_tau_ = nullptr, *lane_a_ = nullptr;
  Lanes *lane_mass_ = nullptr, *lane_com_ = nullptr, *lane_inertia_ = nullptr;  // each lane's bodies
};

}  // namespace freefloat::kernel
