// The articulated-body algorithm (Featherstone, Rigid Body Dynamics Algorithms, 2008, table 7.1)
// on a TreeView: forward dynamics with gravity, joint forces and external wrenches, written out
// component by component for one state (T = double) or for several states of one tree at once
// (T = Lanes, one state per lane: the same operations, in SIMD registers).
//
// Every spatial quantity is in world axes at one reference point, the root joint's origin (the
// world origin on a fixed base), as Pinocchio's WORLD convention but nearer the robot: a body's
// articulated inertia adds to its parent's without a transform, and the numbers do not depend on
// where the robot is. The accelerations of a free or planar root are returned in its own frame,
// as Pinocchio's (the time derivative of its local velocity).
//
// This header is compiled once per instruction set (kernel.cpp: the baseline; lanes_avx2.cpp:
// AVX2, used when the CPU has it; both without fused multiply-adds, so that a lane's numbers are
// a single state's bit for bit): its code lives in the namespace the including unit
// names in FREEFLOAT_KERNEL_ISA, and uses no C++ library template (no function here is shared
// between the units, so the linker never picks an AVX2 copy for a CPU without AVX2). It ends with
// the definitions of kernel/isa.hpp's entry points in that namespace: include it once per unit.
#ifndef FREEFLOAT_KERNEL_ISA
#error "define FREEFLOAT_KERNEL_ISA (a namespace name) before including kernel/aba.hpp"
#endif

#include <math.h>

// A vector of lanes in and out of an inline function of a unit without AVX changes no real call's
// ABI here (every such function is inlined).
#pragma GCC diagnostic ignored "-Wpsabi"

#include "isa.hpp"
#include "tree.hpp"
#include "wrench.hpp"

namespace freefloat::kernel::FREEFLOAT_KERNEL_ISA {

inline double at(double x, int) { return x; }
inline double at(const Lanes& x, int l) { return x[l]; }
inline void put(double& x, int, double value) { x = value; }
inline void put(Lanes& x, int l, double value) { x[l] = value; }
template <class T> constexpr int kWidth = 1;
template <> constexpr int kWidth<Lanes> = 4;

// sin and cos of an angle reduced by the nearest multiple of pi/2 in three parts (Cody and Waite)
// to r in [-pi/4, pi/4]: Cephes' polynomials of r (relative error below 2.3e-16 there), and the
// multiple's quadrant q (0-3).
template <class T>
inline void reduced_sine_cosine(const T& x, T& sin_r, T& cos_r, T& j) {
  const double round = 6755399441055744.0;  // 1.5 2^52: adding and subtracting it rounds to an integer
  j = (x * 0.63661977236758134308 + round) - round;
  const T r = ((x - j * 1.57079625129699707031) - j * 7.54978941586159635335e-8) - j * 5.39030285815811905290e-15;
  const T z = r * r;
  sin_r = r + r * z * (((((1.58962301576546568060e-10 * z - 2.50507477628578072866e-8) * z +
                          2.75573136213857245213e-6) * z - 1.98412698295895385996e-4) * z +
                        8.33333333332211858878e-3) * z - 1.66666666666666307295e-1);
  cos_r = 1.0 - 0.5 * z + z * z * (((((-1.13585365213876817300e-11 * z + 2.08757008419747316778e-9) * z -
                                      2.75573141792967388112e-7) * z + 2.48015872888517045348e-5) * z -
                                    1.38888888888730564116e-3) * z + 4.16666666666665929218e-2);
}

// Angles beyond 1e8 rad (or not finite) take the C library's sincos: the reduction above loses
// digits there.
constexpr double kReducible = 1e8;

inline void sine_cosine(double x, double& s, double& c) {
  if (!(x < kReducible && x > -kReducible)) return sincos(x, &s, &c);
  double sin_r, cos_r, j;
  reduced_sine_cosine(x, sin_r, cos_r, j);
  const long long q = static_cast<long long>(j) & 3;
  const double sine = q & 1 ? cos_r : sin_r, cosine = q & 1 ? sin_r : cos_r;
  s = q >= 2 ? -sine : sine;
  c = q == 1 || q == 2 ? -cosine : cosine;
}

// The same for four angles at once.
inline void sine_cosine(const Lanes& x, Lanes& s, Lanes& c) {
  typedef long long Quadrants __attribute__((vector_size(32)));
  bool reducible = true;
  for (int l = 0; l < 4; ++l) reducible &= x[l] < kReducible && x[l] > -kReducible;
  if (!reducible) {
    for (int l = 0; l < 4; ++l) {
      double sl, cl;
      sine_cosine(x[l], sl, cl);
      s[l] = sl;
      c[l] = cl;
    }
    return;
  }
  Lanes sin_r, cos_r, j;
  reduced_sine_cosine(x, sin_r, cos_r, j);
  const Quadrants q = __builtin_convertvector(j, Quadrants) & 3;
  const Quadrants odd = (q & 1) != 0;
  const Lanes sine = odd ? cos_r : sin_r, cosine = odd ? sin_r : cos_r;
  s = q >= 2 ? -sine : sine;
  c = (q == 1) | (q == 2) ? -cosine : cosine;
}

// out = a x b (out apart from a and b).
template <class T, class U>
inline void cross(const T* a, const U* b, T* out) {
  out[0] = a[1] * b[2] - a[2] * b[1];
  out[1] = a[2] * b[0] - a[0] * b[2];
  out[2] = a[0] * b[1] - a[1] * b[0];
}
// out += a x b.
template <class T, class U>
inline void add_cross(const T* a, const U* b, T* out) {
  out[0] += a[1] * b[2] - a[2] * b[1];
  out[1] += a[2] * b[0] - a[0] * b[2];
  out[2] += a[0] * b[1] - a[1] * b[0];
}
// out = R x, R (3, 3) column by column.
template <class T, class M, class V>
inline void rotate(const M* R, const V* x, T* out) {
  for (int r = 0; r < 3; ++r) out[r] = R[r] * x[0] + R[3 + r] * x[1] + R[6 + r] * x[2];
}
// out = R^T x.
template <class T, class M>
inline void rotate_back(const M* R, const T* x, T* out) {
  for (int k = 0; k < 3; ++k) out[k] = R[3 * k] * x[0] + R[3 * k + 1] * x[1] + R[3 * k + 2] * x[2];
}
template <class T, class U>
inline T dot6(const T* a, const U* b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3] + a[4] * b[4] + a[5] * b[5];
}

// out = I x for the articulated inertia [[A, B], [B^T, C]] (A, C symmetric (xx, yy, zz, xy, xz,
// yz), B column by column).
template <class T, class V>
inline void inertia_times(const T* A, const T* B, const T* C, const V* x, T* out) {
  out[0] = A[0] * x[0] + A[3] * x[1] + A[4] * x[2] + B[0] * x[3] + B[3] * x[4] + B[6] * x[5];
  out[1] = A[3] * x[0] + A[1] * x[1] + A[5] * x[2] + B[1] * x[3] + B[4] * x[4] + B[7] * x[5];
  out[2] = A[4] * x[0] + A[5] * x[1] + A[2] * x[2] + B[2] * x[3] + B[5] * x[4] + B[8] * x[5];
  out[3] = B[0] * x[0] + B[1] * x[1] + B[2] * x[2] + C[0] * x[3] + C[3] * x[4] + C[4] * x[5];
  out[4] = B[3] * x[0] + B[4] * x[1] + B[5] * x[2] + C[3] * x[3] + C[1] * x[4] + C[5] * x[5];
  out[5] = B[6] * x[0] + B[7] * x[1] + B[8] * x[2] + C[4] * x[3] + C[5] * x[4] + C[2] * x[5];
}

// out += S - ud u^T for symmetric 3x3 blocks (xx, yy, zz, xy, xz, yz).
template <class T>
inline void add_downdated(const T* S, const T* u, const T* ud, T* out) {
  out[0] += S[0] - ud[0] * u[0];
  out[1] += S[1] - ud[1] * u[1];
  out[2] += S[2] - ud[2] * u[2];
  out[3] += S[3] - ud[0] * u[1];
  out[4] += S[4] - ud[0] * u[2];
  out[5] += S[5] - ud[1] * u[2];
}

// Body b's frame (R, p) from its parent's (Rp, pp) at q, its motion subspace S and the axis.
template <class T>
inline void place(const TreeView& t, int b, const T* q, const T* Rp, const T* pp, BodyWork<T>& w) {
  const double* RT = t.rot + 9 * b;
  T A[9];  // the joint frame's axes at q = 0: Rp RT
  for (int k = 0; k < 3; ++k) rotate(Rp, RT + 3 * k, A + 3 * k);
  rotate(Rp, t.trans + 3 * b, w.p);
  for (int r = 0; r < 3; ++r) w.p[r] += pp[r];
  const int kind = t.kind[b], axis = t.axis[b];
  T* R = w.R;
  T* S = w.S;
  if (kind == kPrismatic) {
    for (int i = 0; i < 9; ++i) R[i] = A[i];
    T s[3];  // world axis
    if (axis == kGeneral) rotate(A, t.dir + 3 * b, s);
    else
      for (int r = 0; r < 3; ++r) s[r] = t.sign[b] * A[3 * axis + r];
    const T x = q[t.iq[b]];
    for (int r = 0; r < 3; ++r) {
      w.p[r] += x * s[r];
      S[r] = s[r];
      S[3 + r] = T{};
    }
    return;
  }
  T sn, cs;
  if (kind == kUnbounded) {
    cs = q[t.iq[b]];
    sn = q[t.iq[b] + 1];
  } else {
    sine_cosine(q[t.iq[b]], sn, cs);
  }
  T* s = S + 3;
  if (axis == kGeneral) {  // R = A (c I + s [d]x + (1 - c) d d^T), Rodrigues
    const double* d = t.dir + 3 * b;
    const T one_c = 1.0 - cs;
    T J[9];
    J[0] = cs + one_c * d[0] * d[0];
    J[4] = cs + one_c * d[1] * d[1];
    J[8] = cs + one_c * d[2] * d[2];
    J[1] = one_c * d[0] * d[1] + sn * d[2];
    J[3] = one_c * d[0] * d[1] - sn * d[2];
    J[2] = one_c * d[0] * d[2] - sn * d[1];
    J[6] = one_c * d[0] * d[2] + sn * d[1];
    J[5] = one_c * d[1] * d[2] + sn * d[0];
    J[7] = one_c * d[1] * d[2] - sn * d[0];
    for (int k = 0; k < 3; ++k) rotate(A, J + 3 * k, R + 3 * k);
    rotate(A, d, s);
  } else {  // a rotation by the signed angle about axis k: columns i, j of A turn, column k stays
    const int i = (axis + 1) % 3, j = (axis + 2) % 3;
    sn = t.sign[b] * sn;
    for (int r = 0; r < 3; ++r) {
      R[3 * axis + r] = A[3 * axis + r];
      R[3 * i + r] = cs * A[3 * i + r] + sn * A[3 * j + r];
      R[3 * j + r] = cs * A[3 * j + r] - sn * A[3 * i + r];
      s[r] = t.sign[b] * A[3 * axis + r];
    }
  }
  cross(w.p, s, S);  // the axis through the joint origin: [p x s; s]
}

// Body b's spatial inertia in world axes at the reference point (A, B, C), and its bias force
// v x* (I v) (f); its mass, CoM and rotational inertia from `bodies` (tree.hpp's Bodies).
template <class T>
inline void rigid_body(const Bodies<T>& bodies, int b, BodyWork<T>& w) {
  const T m = bodies.mass[b];
  const T* I = bodies.inertia + 6 * b;
  const T Ic[9] = {I[0], I[3], I[4], I[3], I[1], I[5], I[4], I[5], I[2]};
  const T* R = w.R;
  T c[3];  // CoM from the reference point
  rotate(R, bodies.com + 3 * b, c);
  for (int r = 0; r < 3; ++r) c[r] += w.p[r];
  T RI[9];  // R Ic
  for (int k = 0; k < 3; ++k) rotate(R, Ic + 3 * k, RI + 3 * k);
  T Iw[6];  // R Ic R^T, the rotational inertia about the CoM in world axes
  Iw[0] = RI[0] * R[0] + RI[3] * R[3] + RI[6] * R[6];
  Iw[1] = RI[1] * R[1] + RI[4] * R[4] + RI[7] * R[7];
  Iw[2] = RI[2] * R[2] + RI[5] * R[5] + RI[8] * R[8];
  Iw[3] = RI[0] * R[1] + RI[3] * R[4] + RI[6] * R[7];
  Iw[4] = RI[0] * R[2] + RI[3] * R[5] + RI[6] * R[8];
  Iw[5] = RI[1] * R[2] + RI[4] * R[5] + RI[7] * R[8];
  const T h[3] = {m * c[0], m * c[1], m * c[2]};
  w.A[0] = w.A[1] = w.A[2] = m;
  w.A[3] = w.A[4] = w.A[5] = T{};
  w.B[0] = w.B[4] = w.B[8] = T{};  // -m [c]x
  w.B[1] = -h[2];
  w.B[2] = h[1];
  w.B[3] = h[2];
  w.B[5] = -h[0];
  w.B[6] = -h[1];
  w.B[7] = h[0];
  // Iw + m (|c|^2 1 - c c^T), the rotational inertia about the reference point
  w.C[0] = Iw[0] + h[1] * c[1] + h[2] * c[2];
  w.C[1] = Iw[1] + h[0] * c[0] + h[2] * c[2];
  w.C[2] = Iw[2] + h[0] * c[0] + h[1] * c[1];
  w.C[3] = Iw[3] - h[0] * c[1];
  w.C[4] = Iw[4] - h[0] * c[2];
  w.C[5] = Iw[5] - h[1] * c[2];
  // momentum I v = [m (v - c x w); Iw w + c x (m (v - c x w))], bias [w x P; w x L + v x P]
  const T* v = w.v;
  const T* om = w.v + 3;
  T P[3], L[3];
  cross(c, om, P);
  for (int r = 0; r < 3; ++r) P[r] = m * (v[r] - P[r]);
  L[0] = Iw[0] * om[0] + Iw[3] * om[1] + Iw[4] * om[2];
  L[1] = Iw[3] * om[0] + Iw[1] * om[1] + Iw[5] * om[2];
  L[2] = Iw[4] * om[0] + Iw[5] * om[1] + Iw[2] * om[2];
  add_cross(c, P, L);
  cross(om, P, w.f);
  cross(om, L, w.f + 3);
  add_cross(v, P, w.f + 3);
}

// The root's frame and velocity: a free flyer's or a planar joint's, at the reference point (its
// origin). Returns its origin in the world frame.
template <class T>
inline void place_root(const TreeView& t, const T* q, const T* qd, BodyWork<T>& w, T* origin) {
  T Rq[9], pq[3];
  const T* v = qd + t.iv[0];
  if (t.root == kFree) {  // Eigen's Quaternion::toRotationMatrix, as Pinocchio's free flyer
    const T* x = q + t.iq[0];
    const T qx = x[3], qy = x[4], qz = x[5], qw = x[6];
    const T tx = 2.0 * qx, ty = 2.0 * qy, tz = 2.0 * qz;
    const T twx = tx * qw, twy = ty * qw, twz = tz * qw, txx = tx * qx, txy = ty * qx, txz = tz * qx, tyy = ty * qy,
            tyz = tz * qy, tzz = tz * qz;
    Rq[0] = 1.0 - (tyy + tzz);
    Rq[3] = txy - twz;
    Rq[6] = txz + twy;
    Rq[1] = txy + twz;
    Rq[4] = 1.0 - (txx + tzz);
    Rq[7] = tyz - twx;
    Rq[2] = txz - twy;
    Rq[5] = tyz + twx;
    Rq[8] = 1.0 - (txx + tyy);
    for (int r = 0; r < 3; ++r) pq[r] = x[r];
  } else {  // planar: (x, y, cos, sin)
    const T* x = q + t.iq[0];
    const T cs = x[2], sn = x[3];
    Rq[0] = cs;
    Rq[1] = sn;
    Rq[2] = T{};
    Rq[3] = -sn;
    Rq[4] = cs;
    Rq[5] = T{};
    Rq[6] = Rq[7] = T{};
    Rq[8] = T{} + 1.0;
    pq[0] = x[0];
    pq[1] = x[1];
    pq[2] = T{};
  }
  if (t.root_placed) {
    const double* RT = t.rot;
    for (int k = 0; k < 3; ++k) rotate(RT, Rq + 3 * k, w.R + 3 * k);
    rotate(RT, pq, origin);
    for (int r = 0; r < 3; ++r) origin[r] += t.trans[r];
  } else {
    for (int i = 0; i < 9; ++i) w.R[i] = Rq[i];
    for (int r = 0; r < 3; ++r) origin[r] = pq[r];
  }
  for (int r = 0; r < 3; ++r) w.p[r] = T{};
  const T* R = w.R;
  if (t.root == kFree) {
    rotate(R, v, w.v);
    rotate(R, v + 3, w.v + 3);
  } else {
    for (int r = 0; r < 3; ++r) {
      w.v[r] = R[r] * v[0] + R[3 + r] * v[1];
      w.v[3 + r] = R[6 + r] * v[2];
    }
  }
  for (int r = 0; r < 6; ++r) w.c[r] = T{};  // v x v
}

// x = K^-1 x for K (n, n) symmetric positive definite (its lower triangle is overwritten by the
// unit lower factor of K = L D L^T).
template <class T, int n>
inline void ldlt_solve(T (&K)[n][n], T (&x)[n]) {
  T d[n];
  for (int j = 0; j < n; ++j) {
    for (int k = 0; k < j; ++k) {
      const T ld = K[j][k] * d[k];
      for (int i = j; i < n; ++i) K[i][j] -= K[i][k] * ld;
    }
    d[j] = K[j][j];
    const T dinv = 1.0 / d[j];
    for (int i = j + 1; i < n; ++i) K[i][j] *= dinv;
  }
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < i; ++k) x[i] -= K[i][k] * x[k];
  for (int i = 0; i < n; ++i) x[i] /= d[i];
  for (int i = n - 1; i >= 0; --i)
    for (int k = i + 1; k < n; ++k) x[i] -= K[k][i] * x[k];
}

// Subtracts the wrenches of each lane from the bodies' bias forces (after the forward pass).
template <class T>
inline void apply_wrenches(BodyWork<T>* work, const Wrenches* lists) {
  for (int l = 0; l < kWidth<T>; ++l) {
    const Wrenches& list = lists[l];
    for (int k = 0; k < list.count; ++k) {
      const Wrench& x = list.first[k];
      BodyWork<T>& w = work[x.joint - 1];
      double R[9], r[3], F[3], N[3];
      for (int i = 0; i < 9; ++i) R[i] = at(w.R[i], l);
      rotate(R, x.point, r);  // where the force acts, from the reference point
      for (int i = 0; i < 3; ++i) r[i] += at(w.p[i], l);
      if (x.world) {
        for (int i = 0; i < 3; ++i) {
          F[i] = x.force[i];
          N[i] = x.torque[i];
        }
      } else {
        rotate(R, x.force, F);
        rotate(R, x.torque, N);
      }
      add_cross(r, F, N);
      for (int i = 0; i < 3; ++i) {
        put(w.f[i], l, at(w.f[i], l) - F[i]);
        put(w.f[3 + i], l, at(w.f[3 + i], l) - N[i]);
      }
    }
  }
}

// qdd (nv,) = forward dynamics at (q, qd) under joint forces tau (nv,) and the wrenches (one list
// per lane; null: none), gravity t.gravity, with the bodies' masses and inertias `bodies`. `work`
// holds t.nb bodies.
template <class T>
void aba(const TreeView& t, const Bodies<T>& bodies, BodyWork<T>* work, const T* q, const T* qd, const T* tau,
         const Wrenches* wrenches, T* qdd) {
  const int nb = t.nb;
  const bool floating = t.root != kFixed;
  // The universe from the reference point: its axes, origin, and acceleration (gravity's opposite).
  static const double kIdentity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  T R0[9], p0[3] = {T{}, T{}, T{}}, a0[6];
  for (int i = 0; i < 9; ++i) R0[i] = T{} + kIdentity[i];
  for (int r = 0; r < 3; ++r) {
    a0[r] = T{} - t.gravity[r];
    a0[3 + r] = T{};
  }
  const int first = floating ? 1 : 0;
  if (floating) {
    BodyWork<T>& w = work[0];
    T origin[3];
    place_root(t, q, qd, w, origin);
    for (int r = 0; r < 3; ++r) p0[r] = -origin[r];
    rigid_body(bodies, 0, w);
  }
  // 1. Kinematics, velocities, rigid inertias and bias forces, parents first.
  for (int b = first; b < nb; ++b) {
    BodyWork<T>& w = work[b];
    const int parent = t.parent[b];
    const T* Rp = parent < 0 ? R0 : work[parent].R;
    const T* pp = parent < 0 ? p0 : work[parent].p;
    place(t, b, q, Rp, pp, w);
    const T x = qd[t.iv[b]];
    T Sx[6];
    for (int r = 0; r < 6; ++r) Sx[r] = w.S[r] * x;
    if (parent < 0) {
      for (int r = 0; r < 6; ++r) w.v[r] = Sx[r];
      for (int r = 0; r < 6; ++r) w.c[r] = T{};
    } else {
      const T* vp = work[parent].v;
      for (int r = 0; r < 6; ++r) w.v[r] = vp[r] + Sx[r];
      cross(vp + 3, Sx, w.c);  // v x (S qd) = vp x (S qd)
      add_cross(vp, Sx + 3, w.c);
      cross(vp + 3, Sx + 3, w.c + 3);
    }
    rigid_body(bodies, b, w);
  }
  if (wrenches != nullptr) apply_wrenches(work, wrenches);
  // 2. Articulated inertias and bias forces, children first.
  for (int b = nb - 1; b >= first; --b) {
    BodyWork<T>& w = work[b];
    inertia_times(w.A, w.B, w.C, w.S, w.U);
    const int iv = t.iv[b];
    w.dinv = 1.0 / (dot6(w.S, w.U) + t.armature[iv]);
    w.u = tau[iv] - dot6(w.S, w.f);
    const int parent = t.parent[b];
    if (parent < 0) continue;
    BodyWork<T>& P = work[parent];
    T Ic[6];
    inertia_times(w.A, w.B, w.C, w.c, Ic);
    const T* U = w.U;
    const T g = w.dinv * (w.u - dot6(U, w.c));
    for (int r = 0; r < 6; ++r) P.f[r] += w.f[r] + Ic[r] + U[r] * g;
    T Ud[6];
    for (int r = 0; r < 6; ++r) Ud[r] = U[r] * w.dinv;
    add_downdated(w.A, U, Ud, P.A);
    for (int k = 0; k < 3; ++k)
      for (int r = 0; r < 3; ++r) P.B[3 * k + r] += w.B[3 * k + r] - Ud[r] * U[3 + k];
    add_downdated(w.C, U + 3, Ud + 3, P.C);
  }
  // 3. The root's acceleration, then every body's, parents first.
  if (t.root == kFree) {
    BodyWork<T>& w = work[0];
    const T* R = w.R;
    const int iv = t.iv[0];
    T K[6][6], x[6], Ia0[6], ft[6];
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        K[i][3 + j] = w.B[3 * j + i];
        K[3 + j][i] = w.B[3 * j + i];
      }
    }
    const int sym[3][3] = {{0, 3, 4}, {3, 1, 5}, {4, 5, 2}};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        K[i][j] = w.A[sym[i][j]];
        K[3 + i][3 + j] = w.C[sym[i][j]];
      }
    if (t.root_armature) {  // K += S diag(armature) S^T, S = diag(R, R)
      for (int h = 0; h < 2; ++h)
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) {
            T sum = T{};
            for (int k = 0; k < 3; ++k) sum += R[3 * k + i] * t.armature[iv + 3 * h + k] * R[3 * k + j];
            K[3 * h + i][3 * h + j] += sum;
          }
    }
    inertia_times(w.A, w.B, w.C, a0, Ia0);
    rotate(R, tau + iv, ft);  // S tau
    rotate(R, tau + iv + 3, ft + 3);
    for (int r = 0; r < 6; ++r) x[r] = ft[r] - w.f[r] - Ia0[r];
    ldlt_solve(K, x);
    for (int r = 0; r < 6; ++r) w.a[r] = a0[r] + x[r];
    rotate_back(R, x, qdd + iv);
    rotate_back(R, x + 3, qdd + iv + 3);
  } else if (t.root == kPlanar) {
    BodyWork<T>& w = work[0];
    const T* R = w.R;
    const int iv = t.iv[0];
    T S[3][6], U[3][6], D[3][3], x[3];
    for (int r = 0; r < 3; ++r) {
      S[0][r] = R[r];
      S[1][r] = R[3 + r];
      S[2][r] = T{};
      S[0][3 + r] = S[1][3 + r] = T{};
      S[2][3 + r] = R[6 + r];
    }
    for (int k = 0; k < 3; ++k) inertia_times(w.A, w.B, w.C, S[k], U[k]);
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) D[i][j] = dot6(S[i], U[j]);
      D[i][i] += t.armature[iv + i];
      x[i] = tau[iv + i] - dot6(S[i], w.f) - dot6(U[i], a0);
    }
    ldlt_solve(D, x);
    for (int r = 0; r < 6; ++r) w.a[r] = a0[r] + S[0][r] * x[0] + S[1][r] * x[1] + S[2][r] * x[2];
    for (int i = 0; i < 3; ++i) qdd[iv + i] = x[i];
  }
  for (int b = first; b < nb; ++b) {
    BodyWork<T>& w = work[b];
    const int parent = t.parent[b];
    const T* ap = parent < 0 ? a0 : work[parent].a;
    for (int r = 0; r < 6; ++r) w.a[r] = ap[r] + w.c[r];
    const T x = w.dinv * (w.u - dot6(w.U, w.a));
    for (int r = 0; r < 6; ++r) w.a[r] += w.S[r] * x;
    qdd[t.iv[b]] = x;
  }
}

void aba_one(const TreeView& tree, const Bodies<double>& bodies, BodyWork<double>* work, const double* q,
             const double* qd, const double* tau, const Wrenches* wrenches, double* qdd) {
  aba(tree, bodies, work, q, qd, tau, wrenches, qdd);
}

void aba_lanes(const TreeView& tree, const Bodies<Lanes>& bodies, BodyWork<Lanes>* work, const Lanes* q,
               const Lanes* qd, const Lanes* tau, const Wrenches* wrenches, Lanes* qdd) {
  aba(tree, bodies, work, q, qd, tau, wrenches, qdd);
}

}  // namespace freefloat::kernel::FREEFLOAT_KERNEL_ISA
