// The dynamics kernel (kernel/kernel.hpp): the tree read from the model's arrays once, the
// evaluation of kernel/aba.hpp compiled for the platform's baseline here (its entry points in
// namespace baseline), and the choice, on this CPU, between it and the AVX2 unit's (lanes_avx2.cpp).
#define FREEFLOAT_KERNEL_ISA baseline
#include "aba.hpp"

#include <atomic>
#include <cmath>
#include <cstdint>
#include <new>
#include <stdexcept>
#include <string>
#include <utility>

#include "isa.hpp"
#include "kernel.hpp"
#include "sim/model_arrays.hpp"

namespace freefloat::kernel {

namespace {

// Whether this CPU runs the AVX2 unit, asked once.
bool has_avx2() {
#if defined(__x86_64__) || defined(__i386__)
  static const bool yes = __builtin_cpu_supports("avx2");
  return yes;
#else
  return false;
#endif
}

std::atomic<bool> baseline_only{false};  // Kernel::set_isa("baseline")

// Whether evaluations take the AVX2 unit.
bool avx2_now() { return has_avx2() && !baseline_only.load(std::memory_order_relaxed); }

// A joint kind of Pinocchio's as the kernel has it.
struct JointKind {
  int root = kFixed;  // kFree, kPlanar: a root joint
  int kind = kRevolute, axis = kGeneral;
  double sign = 1.0;
  int nq = 1, nv = 1;
  bool known = true;
};

JointKind kind_named(const std::string& name) {
  JointKind k;
  if (name == "JointModelFreeFlyer") return {kFree, kRevolute, kGeneral, 1.0, 7, 6, true};
  if (name == "JointModelPlanar") return {kPlanar, kRevolute, kGeneral, 1.0, 4, 3, true};
  const std::string tail = name.size() > 10 ? name.substr(10) : "";  // after "JointModel"
  if (tail == "RX" || tail == "RY" || tail == "RZ") k.axis = tail[1] - 'X';
  else if (tail == "RUBX" || tail == "RUBY" || tail == "RUBZ") k = {kFixed, kUnbounded, tail[3] - 'X', 1.0, 2, 1, true};
  else if (tail == "PX" || tail == "PY" || tail == "PZ") k = {kFixed, kPrismatic, tail[1] - 'X', 1.0, 1, 1, true};
  else if (tail == "RevoluteUnaligned") k.kind = kRevolute;
  else if (tail == "RevoluteUnboundedUnaligned") k = {kFixed, kUnbounded, kGeneral, 1.0, 2, 1, true};
  else if (tail == "PrismaticUnaligned") k.kind = kPrismatic;
  else k.known = false;
  return k;
}

// Column-major rotation and translation of the row-major homogeneous transform H (4, 4).
void placement_of(const double* H, double* rot, double* trans) {
  for (int k = 0; k < 3; ++k)
    for (int r = 0; r < 3; ++r) rot[3 * k + r] = H[4 * r + k];
  for (int r = 0; r < 3; ++r) trans[r] = H[4 * r + 3];
}

// (xx, yy, zz, xy, xz, yz) of the row-major (3, 3) I.
void symmetric_of(const double* I, double* out) {
  const double s[6] = {I[0], I[4], I[8], I[1], I[2], I[5]};
  for (int i = 0; i < 6; ++i) out[i] = s[i];
}

}  // namespace

Kernel::~Kernel() = default;

std::unique_ptr<Kernel> Kernel::build(const sim::ModelArrays& a, std::string* why) {
  const size_t n = a.parent.size();
  if (a.kind.size() != n || a.name.size() != n)
    throw std::invalid_argument("parent, kind, name: expected one entry per joint");
  std::unique_ptr<Kernel> k(new Kernel);
  TreeView& t = k->tree_;
  t.nb = static_cast<int>(n);
  for (size_t j = 0; j < n; ++j) {
    const JointKind jk = kind_named(a.kind[j]);
    const std::string joint = "joint '" + a.name[j] + "' ";
    if (!jk.known || (jk.root != kFixed && (j != 0 || a.parent[j] != 0))) {
      if (why != nullptr)
        *why = joint + (jk.known ? "is a " + a.kind[j] + " that is not the root"
                                 : "is a " + a.kind[j] + ", which the dynamics kernel does not have");
      return nullptr;
    }
    if (a.parent[j] < 0 || a.parent[j] > static_cast<int>(j))
      throw std::invalid_argument(joint + ": its parent must come before it");
    if (jk.root != kFixed) t.root = jk.root;
    double dir[3] = {0.0, 0.0, 0.0};
    int axis = jk.axis;
    double sign = jk.sign;
    if (jk.root == kFixed && axis == kGeneral) {  // the unit axis of the subspace, as pin_plant's make_joint
      const double* S = a.subspace + 6 * j + (jk.kind == kPrismatic ? 0 : 3);
      const double norm = std::sqrt(S[0] * S[0] + S[1] * S[1] + S[2] * S[2]);
      if (!(norm > 0.0)) throw std::invalid_argument(joint + "has no axis");
      for (int r = 0; r < 3; ++r) dir[r] = S[r] / norm;
      for (int r = 0; r < 3; ++r)  // an axis of the joint frame after all: its column of R
        if (std::abs(dir[r]) == 1.0 && dir[(r + 1) % 3] == 0.0 && dir[(r + 2) % 3] == 0.0) {
          axis = r;
          sign = dir[r];
        }
    }
    k->parent_.push_back(a.parent[j] - 1);
    k->kind_.push_back(jk.kind);
    k->axis_.push_back(axis);
    k->sign_.push_back(sign);
    k->dir_.insert(k->dir_.end(), dir, dir + 3);
    k->iq_.push_back(t.nq);
    k->iv_.push_back(t.nv);
    t.nq += jk.nq;
    t.nv += jk.nv;
  }
  k->rot_.resize(9 * n);
  k->trans_.resize(3 * n);
  k->mass_.resize(n);
  k->com_.resize(3 * n);
  k->inertia_.resize(6 * n);
  k->allocate();
  k->read(a);
  return k;
}

void Kernel::allocate() {
  const size_t n = parent_.size();
  work_.resize(n);
  // the lockstep workspace, then q, v, tau, a and the lanes' bodies, each at 32 bytes
  const size_t lanes = tree_.nq + 3 * tree_.nv + 10 * n, width = sizeof(Lanes) / sizeof(double);
  lane_buffer_.assign(n * sizeof(BodyWork<Lanes>) / sizeof(double) + width * (lanes + 1), 0.0);
  const uintptr_t start = (reinterpret_cast<uintptr_t>(lane_buffer_.data()) + 31) & ~uintptr_t{31};
  lane_work_ = reinterpret_cast<BodyWork<Lanes>*>(start);
  for (size_t b = 0; b < n; ++b) new (lane_work_ + b) BodyWork<Lanes>;
  lane_q_ = new (lane_work_ + n) Lanes[lanes];
  lane_v_ = lane_q_ + tree_.nq;
  lane_tau_ = lane_v_ + tree_.nv;
  lane_a_ = lane_tau_ + tree_.nv;
  lane_mass_ = lane_a_ + tree_.nv;
  lane_com_ = lane_mass_ + n;
  lane_inertia_ = lane_com_ + 3 * n;
}

std::unique_ptr<Kernel> Kernel::clone() const {
  std::unique_ptr<Kernel> k(new Kernel);
  k->tree_ = tree_;
  k->parent_ = parent_;
  k->kind_ = kind_;
  k->axis_ = axis_;
  k->iq_ = iq_;
  k->iv_ = iv_;
  k->sign_ = sign_;
  k->dir_ = dir_;
  k->rot_ = rot_;
  k->trans_ = trans_;
  k->armature_ = armature_;
  k->mass_ = mass_;
  k->com_ = com_;
  k->inertia_ = inertia_;
  k->allocate();
  for (size_t i = 0; i < 10 * parent_.size(); ++i) k->lane_mass_[i] = lane_mass_[i];  // mass, com, inertia
  k->tree_ = k->view();
  return k;
}

void Kernel::read(const sim::ModelArrays& a) {
  const size_t n = parent_.size();
  if (a.armature_size != tree_.nv) throw std::invalid_argument("armature: expected one entry per velocity");
  for (size_t j = 0; j < n; ++j) {
    placement_of(a.placement + 16 * j, &rot_[9 * j], &trans_[3 * j]);
    mass_[j] = a.mass[j];
    for (int r = 0; r < 3; ++r) com_[3 * j + r] = a.lever[3 * j + r];
    symmetric_of(a.rotational + 9 * j, &inertia_[6 * j]);
  }
  for (int l = 0; l < kLanes; ++l) copy_lane_bodies(l);
  armature_.assign(a.armature, a.armature + tree_.nv);
  for (int r = 0; r < 3; ++r) tree_.gravity[r] = a.gravity[r];
  tree_.root_placed = tree_.root_armature = false;
  for (int i = 0; tree_.root != kFixed && i < 12; ++i)  // the root placement against the identity
    tree_.root_placed |= (i < 9 ? rot_[i] : trans_[i - 9]) != (i < 9 && i % 4 == 0 ? 1.0 : 0.0);
  for (int i = 0; tree_.root != kFixed && i < (tree_.root == kFree ? 6 : 3); ++i)
    tree_.root_armature |= armature_[i] != 0.0;
  tree_ = view();
}

TreeView Kernel::view() const {
  TreeView t = tree_;
  t.parent = parent_.data();
  t.kind = kind_.data();
  t.axis = axis_.data();
  t.iq = iq_.data();
  t.iv = iv_.data();
  t.sign = sign_.data();
  t.dir = dir_.data();
  t.rot = rot_.data();
  t.trans = trans_.data();
  t.armature = armature_.data();
  return t;
}

void Kernel::set_numbers(const sim::ModelArrays& arrays) {
  const std::unique_ptr<Kernel> other = build(arrays);
  if (!other || other->parent_ != parent_ || other->kind_ != kind_ || other->axis_ != axis_ ||
      other->sign_ != sign_ || other->dir_ != dir_ || other->tree_.root != tree_.root)
    throw std::invalid_argument("the model's joints differ from the kernel's");
  read(arrays);
}

void Kernel::set_bodies(const double* bodies) {
  for (int b = 0; b < tree_.nb; ++b, bodies += 13) {
    mass_[b] = bodies[0];
    for (int r = 0; r < 3; ++r) com_[3 * b + r] = bodies[1 + r];
    symmetric_of(bodies + 4, &inertia_[6 * b]);
  }
  for (int l = 0; l < kLanes; ++l) copy_lane_bodies(l);
}

void Kernel::set_lane_bodies(int lane, const double* bodies) {
  for (int b = 0; b < tree_.nb; ++b, bodies += 13) {
    lane_mass_[b][lane] = bodies[0];
    for (int r = 0; r < 3; ++r) lane_com_[3 * b + r][lane] = bodies[1 + r];
    double I[6];
    symmetric_of(bodies + 4, I);
    for (int i = 0; i < 6; ++i) lane_inertia_[6 * b + i][lane] = I[i];
  }
}

void Kernel::copy_lane_bodies(int lane) {
  for (int b = 0; b < tree_.nb; ++b) {
    lane_mass_[b][lane] = mass_[b];
    for (int r = 0; r < 3; ++r) lane_com_[3 * b + r][lane] = com_[3 * b + r];
    for (int i = 0; i < 6; ++i) lane_inertia_[6 * b + i][lane] = inertia_[6 * b + i];
  }
}

void Kernel::aba(const double* q, const double* v, const double* tau, const Wrenches& wrenches, double* a) {
  const Wrenches* w = wrenches.count > 0 ? &wrenches : nullptr;
  const Bodies<double> bodies{mass_.data(), com_.data(), inertia_.data()};
  if (avx2_now()) avx2::aba_one(tree_, bodies, work_.data(), q, v, tau, w, a);
  else baseline::aba_one(tree_, bodies, work_.data(), q, v, tau, w, a);
}

void Kernel::aba_lanes(const double* const* q, const double* const* v, const double* const* tau,
                       const Wrenches* wrenches, double* const* a) {
  const int nq = tree_.nq, nv = tree_.nv;
  for (int l = 0; l < kLanes; ++l) {
    for (int i = 0; i < nq; ++i) lane_q_[i][l] = q[l][i];
    for (int i = 0; i < nv; ++i) {
      lane_v_[i][l] = v[l][i];
      lane_tau_[i][l] = tau[l][i];
    }
  }
  bool any = false;
  for (int l = 0; wrenches != nullptr && l < kLanes; ++l) any |= wrenches[l].count > 0;
  const Wrenches* w = any ? wrenches : nullptr;
  const Bodies<Lanes> bodies{lane_mass_, lane_com_, lane_inertia_};
  if (avx2_now()) avx2::aba_lanes(tree_, bodies, lane_work_, lane_q_, lane_v_, lane_tau_, w, lane_a_);
  else baseline::aba_lanes(tree_, bodies, lane_work_, lane_q_, lane_v_, lane_tau_, w, lane_a_);
  for (int l = 0; l < kLanes; ++l)
    for (int i = 0; i < nv; ++i) a[l][i] = lane_a_[i][l];
}

const char* Kernel::isa() { return avx2_now() ? "avx2" : "baseline"; }

void Kernel::set_isa(const std::string& name) {
  if (name == "avx2" && !has_avx2()) throw std::invalid_argument("this CPU has no AVX2");
  if (name != "avx2" && name != "baseline") throw std::invalid_argument("instruction set must be 'avx2' or 'baseline'");
  baseline_only = name == "baseline";
}

}  // namespace freefloat::kernel
