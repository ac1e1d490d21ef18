// The bundled Gough-Stewart's actuator forces by Pinocchio on the opened tree, checked against the
// generated `inverse_dynamics` (data/VARIANT.txt from src/main.rs: x, u, ud, q, tau per line) and
// timed. Header-only Pinocchio (no libpinocchio_*: the model is built here, not parsed), so the
// whole program is built with -O3 -march=native. The equations: ../README.md, "Gough–Stewart".
//
// Tree (Pinocchio): joint 1 a free-flyer carrying the platform; leg k (0..5): RUBX (unbounded
// revolute about x, q = (cos, sin)) at the U centre b_k with the U frame R0_k, RUBY (the cylinder),
// PZ (the piston, the actuated joint); the S joints cut. q = [p; quaternion (x, y, z, w); per leg
// (cos α, sin α, cos β, sin β, d)], nq = 37; v = [v_ff (6: linear, angular, platform frame);
// leg 0 (α̇, β̇, ḋ); ...], nv = 24.
//
// Routes, each from (x, u, ud) to the six actuator forces:
//   "jac": closed-form leg IK; computeJointJacobians + getFrameJacobian (LOCAL_WORLD_ALIGNED) of
//     each leg tip, a 3x3 solve per leg for the leg rates; forwardKinematics(q, v, 0) +
//     getFrameClassicalAcceleration for each tip's drift J̇θ̇ and a 3x3 solve for the leg
//     accelerations; rnea; the projection f = A⁻ᵀ Tᵀ τ with the legs' J⁻ᵀ (Eigen PartialPivLU).
//   "closed": the same with the leg Jacobians, their inverses and drifts in closed form (the U's
//     columns are orthogonal): Pinocchio's only work is one rnea.
//   "cg": "closed" with Pinocchio's CodeGenRNEA (CppADCodeGen) of the same tree for the rnea.
//   "cg-whole": "closed" written for any scalar (forces_t) and taped whole on Pinocchio's AD model
//     (a CodeGenBase, as CodeGenRNEA is built): one generated C function (x, u, ud) -> forces.
// Usage: gs_bench "GCC FLAGS" LIBDIR (the flags for CppADCodeGen's C; libraries in LIBDIR/VARIANT).
#include <pinocchio/codegen/cppadcg.hpp>  // before the other Pinocchio headers
#include <pinocchio/codegen/cppadcg-algo.hpp>
#include <pinocchio/multibody.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/algorithm/jacobian.hpp>
#include <pinocchio/algorithm/kinematics.hpp>
#include <pinocchio/algorithm/frames.hpp>
#include <Eigen/LU>
#include <algorithm>
#include <chrono>
#include <ctime>
#include <filesystem>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>
#include "gs_model.hpp"

using namespace pinocchio;
using V3 = Eigen::Vector3d;
using M3 = Eigen::Matrix3d;
using V6 = Eigen::Matrix<double, 6, 1>;
using M6 = Eigen::Matrix<double, 6, 6>;

struct Spec { const double *gravity; const Body *platform; const Leg *legs; };

static Inertia inertia(const Body &b) {
  M3 I;
  I << b.inertia[0], b.inertia[1], b.inertia[2], b.inertia[1], b.inertia[3], b.inertia[4], b.inertia[2],
      b.inertia[4], b.inertia[5];
  return Inertia(b.mass, V3(b.com[0], b.com[1], b.com[2]), I);
}

static Model build(const Spec &s) {
  Model m;
  m.gravity = Motion(V3(s.gravity[0], s.gravity[1], s.gravity[2]), V3::Zero());
  JointIndex ff = m.addJoint(0, JointModelFreeFlyer(), SE3::Identity(), "platform");
  m.appendBodyToJoint(ff, inertia(*s.platform), SE3::Identity());
  for (int k = 0; k < 6; ++k) {
    const Leg &L = s.legs[k];
    M3 R0 = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(L.R0);
    std::string n = std::to_string(k + 1);
    // The U's revolutes as Pinocchio's unbounded revolutes (q = (cos, sin)): the leg's closed form
    // gives the cosines and sines, so neither side takes an atan2, asin, sin or cos.
    JointIndex a = m.addJoint(0, JointModelRUBX(), SE3(R0, V3(L.b[0], L.b[1], L.b[2])), "u" + n + "_1");
    JointIndex b = m.addJoint(a, JointModelRUBY(), SE3::Identity(), "u" + n + "_2");
    m.appendBodyToJoint(b, inertia(L.cylinder), SE3::Identity());
    JointIndex p = m.addJoint(b, JointModelPZ(), SE3::Identity(), "p" + n);
    m.appendBodyToJoint(p, inertia(L.piston), SE3::Identity());
  }
  return m;
}

// Constants of the legs, in Eigen types.
struct Legs {
  M3 R0[6];
  V3 b[6], p[6];
  double tip[6];
  SE3 tipPlace[6];
  explicit Legs(const Spec &s) {
    for (int k = 0; k < 6; ++k) {
      const Leg &L = s.legs[k];
      R0[k] = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(L.R0);
      b[k] = V3(L.b[0], L.b[1], L.b[2]);
      p[k] = V3(L.p[0], L.p[1], L.p[2]);
      tip[k] = L.tip;
      tipPlace[k] = SE3(M3::Identity(), V3(0, 0, L.tip));
    }
  }
};

struct State { double x[7], u[6], ud[6], q[6], tau[6]; };

// Everything a route needs per call, allocated once.
struct Work {
  const Model &m;
  Data d;
  Eigen::VectorXd q, v, a, zero;
  Data::Matrix6x J;
  Work(const Model &m_) : m(m_), d(m_), q(m_.nq), v(m_.nv), a(m_.nv), zero(Eigen::VectorXd::Zero(m_.nv)), J(6, m_.nv) {
    J.setZero();
  }
};

// Platform quantities and the closed-form leg inverse kinematics (both routes).
struct Pose {
  M3 R;
  V3 w, v, wd, vd;   // u = [w; v], ud = [wd; vd] (base frame; v the platform origin's velocity)
  V3 r[6];           // R p_k
  V3 l[6];           // the leg vector in its U frame, R0ᵀ (p + R p_k − b_k)
  double rho[6];     // its length
  double sa[6], ca[6], sb[6], cb[6];  // the U angles' sines and cosines
};

static inline void pose(const Legs &G, const State &s, Pose &P, Work &W) {
  Eigen::Quaterniond Q(s.x[3], s.x[4], s.x[5], s.x[6]);
  P.R = Q.toRotationMatrix();
  P.w = V3(s.u[0], s.u[1], s.u[2]); P.v = V3(s.u[3], s.u[4], s.u[5]);
  P.wd = V3(s.ud[0], s.ud[1], s.ud[2]); P.vd = V3(s.ud[3], s.ud[4], s.ud[5]);
  const V3 p0(s.x[0], s.x[1], s.x[2]);
  W.q.head<3>() = p0;
  W.q.segment<4>(3) << s.x[4], s.x[5], s.x[6], s.x[3];  // Pinocchio: (x, y, z, w)
  const V3 wl = P.R.transpose() * P.w, vl = P.R.transpose() * P.v;
  W.v.head<3>() = vl; W.v.segment<3>(3) = wl;
  W.a.head<3>() = P.R.transpose() * P.vd - wl.cross(vl);  // d/dt of the local velocity
  W.a.segment<3>(3) = P.R.transpose() * P.wd;
  for (int k = 0; k < 6; ++k) {
    P.r[k] = P.R * G.p[k];
    P.l[k] = G.R0[k].transpose() * (p0 + P.r[k] - G.b[k]);
    P.rho[k] = P.l[k].norm();
    const V3 sk = P.l[k] / P.rho[k];
    // R0 Rx(α) Ry(β) e_z = R0 [sin β, −sin α cos β, cos α cos β]: the branch through 0 at home
    // (cos β > 0).
    const double sb = sk[0], cb = std::sqrt(sk[1] * sk[1] + sk[2] * sk[2]);
    P.sb[k] = sb; P.cb[k] = cb; P.sa[k] = -sk[1] / cb; P.ca[k] = sk[2] / cb;
    W.q.segment<5>(7 + 5 * k) << P.ca[k], P.sa[k], cb, sb, P.rho[k] - G.tip[k];
  }
}

// f = Tᵀ τ_tree (leg tip forces wk, world) and τ_act = A⁻ᵀ f (A's rows [(r × g)ᵀ, gᵀ], g the
// world direction whose dot product with the tip velocity is the prismatic rate).
static inline V6 project(const Pose &P, const V3 *wk, const V3 *g, const Eigen::VectorXd &tau) {
  V6 f;
  f.head<3>() = P.R * tau.segment<3>(3);  // the free-flyer's [force; moment] (platform frame)
  f.tail<3>() = P.R * tau.head<3>();
  M6 At;  // Aᵀ
  for (int k = 0; k < 6; ++k) {
    f.head<3>() += P.r[k].cross(wk[k]);
    f.tail<3>() += wk[k];
    At.col(k).head<3>() = P.r[k].cross(g[k]);
    At.col(k).tail<3>() = g[k];
  }
  return Eigen::PartialPivLU<M6>(At).solve(f);
}

// Route "pinocchio-jac".
static V6 route_jac(const Legs &G, const State &s, Work &W) {
  Pose P;
  pose(G, s, P, W);
  computeJointJacobians(W.m, W.d, W.q);
  M3 Jinv[6];
  for (int k = 0; k < 6; ++k) {
    const JointIndex jp = 4 + 3 * k;
    getFrameJacobian(W.m, W.d, jp, G.tipPlace[k], LOCAL_WORLD_ALIGNED, W.J);
    Jinv[k] = W.J.block<3, 3>(0, 6 + 3 * k).inverse();
    W.v.segment<3>(6 + 3 * k) = Jinv[k] * (P.v + P.w.cross(P.r[k]));
  }
  forwardKinematics(W.m, W.d, W.q, W.v, W.zero);
  for (int k = 0; k < 6; ++k) {
    const JointIndex jp = 4 + 3 * k;
    const V3 drift = getFrameClassicalAcceleration(W.m, W.d, jp, G.tipPlace[k], LOCAL_WORLD_ALIGNED).linear();
    const V3 at = P.vd + P.wd.cross(P.r[k]) + P.w.cross(P.w.cross(P.r[k]));
    W.a.segment<3>(6 + 3 * k) = Jinv[k] * (at - drift);
  }
  const Eigen::VectorXd &tau = rnea(W.m, W.d, W.q, W.v, W.a);
  V3 wk[6], g[6];
  for (int k = 0; k < 6; ++k) {
    wk[k] = Jinv[k].transpose() * tau.segment<3>(6 + 3 * k);
    g[k] = Jinv[k].row(2).transpose();
  }
  return project(P, wk, g, tau);
}

// Route "pinocchio-closed": J = R0 [ρ e_α, ρ e_β, s] (orthogonal columns, |e_α| = cos β).
template <class Rnea> static V6 route_closed(const Legs &G, const State &s, Work &W, Rnea &&rnea_of) {
  Pose P;
  pose(G, s, P, W);
  V3 ea[6], eb[6], sv[6];
  for (int k = 0; k < 6; ++k) {
    const double rho = P.rho[k];
    const V3 sk = P.l[k] / rho;
    const double sb = P.sb[k], cb = P.cb[k], sa = P.sa[k], ca = P.ca[k];
    ea[k] = V3(0, -ca * cb, -sa * cb); eb[k] = V3(cb, sa * sb, -ca * sb); sv[k] = sk;
    const M3 &R0 = G.R0[k];
    const V3 ld = R0.transpose() * (P.v + P.w.cross(P.r[k]));
    const V3 ldd = R0.transpose() * (P.vd + P.wd.cross(P.r[k]) + P.w.cross(P.w.cross(P.r[k])));
    const double ka = 1.0 / (rho * cb * cb), kb = 1.0 / rho;
    const double ad = ka * ea[k].dot(ld), bd = kb * eb[k].dot(ld), dd = sk.dot(ld);
    const V3 Saa(0, sa * cb, -ca * cb), Sab(0, ca * sb, sa * sb), Sbb(-sb, sa * cb, -ca * cb);
    const V3 drift = 2 * dd * (ad * ea[k] + bd * eb[k]) + rho * (ad * ad * Saa + 2 * ad * bd * Sab + bd * bd * Sbb);
    const V3 r = ldd - drift;
    W.v.segment<3>(6 + 3 * k) << ad, bd, dd;
    W.a.segment<3>(6 + 3 * k) << ka * ea[k].dot(r), kb * eb[k].dot(r), sk.dot(r);
    ea[k] *= ka; eb[k] *= kb;  // now the rows of J⁻¹ (U frame)
  }
  const Eigen::VectorXd &tau = rnea_of(W);
  V3 wk[6], g[6];
  for (int k = 0; k < 6; ++k) {
    const V3 tl = tau[6 + 3 * k] * ea[k] + tau[7 + 3 * k] * eb[k] + tau[8 + 3 * k] * sv[k];
    wk[k] = G.R0[k] * tl;
    g[k] = G.R0[k] * sv[k];
  }
  return project(P, wk, g, tau);
}


// The closed route as one function of any scalar (double, or CppAD's AD<CG<double>> to tape it):
// in = [x (7), u (6), ud (6)] to the six forces. The 6x6 system Aᵀ τ = f by Gaussian elimination
// in a fixed order (rows: force, then moment; no pivot search, which a tape cannot record); the
// accuracy check below is what shows this order is good enough on the states here.
template <class S> struct LegsT {
  Eigen::Matrix<S, 3, 3> R0[6];
  Eigen::Matrix<S, 3, 1> b[6], p[6];
  S tip[6];
  explicit LegsT(const Legs &G) {
    for (int k = 0; k < 6; ++k) {
      R0[k] = G.R0[k].cast<S>(); b[k] = G.b[k].cast<S>(); p[k] = G.p[k].cast<S>(); tip[k] = S(G.tip[k]);
    }
  }
};

template <class S, class ModelT, class DataT, class In, class VX>
static Eigen::Matrix<S, 6, 1> forces_t(const ModelT &m, DataT &d, const LegsT<S> &G, const In &in, VX &q, VX &v, VX &a) {
  using std::sqrt;
  using V = Eigen::Matrix<S, 3, 1>;
  using M = Eigen::Matrix<S, 3, 3>;
  const S qw = in[3], qx = in[4], qy = in[5], qz = in[6];
  const S one(1), two(2);
  M R;
  R << one - two * (qy * qy + qz * qz), two * (qx * qy - qz * qw), two * (qx * qz + qy * qw),
      two * (qx * qy + qz * qw), one - two * (qx * qx + qz * qz), two * (qy * qz - qx * qw),
      two * (qx * qz - qy * qw), two * (qy * qz + qx * qw), one - two * (qx * qx + qy * qy);
  const V p0(in[0], in[1], in[2]), w(in[7], in[8], in[9]), vel(in[10], in[11], in[12]);
  const V wd(in[13], in[14], in[15]), vd(in[16], in[17], in[18]);
  q[0] = p0[0]; q[1] = p0[1]; q[2] = p0[2]; q[3] = qx; q[4] = qy; q[5] = qz; q[6] = qw;
  const V wl = R.transpose() * w, vl = R.transpose() * vel;
  const V al = R.transpose() * vd - wl.cross(vl), wdl = R.transpose() * wd;
  for (int i = 0; i < 3; ++i) { v[i] = vl[i]; v[3 + i] = wl[i]; a[i] = al[i]; a[3 + i] = wdl[i]; }
  V r[6], ea[6], eb[6], sv[6];
  for (int k = 0; k < 6; ++k) {
    r[k] = R * G.p[k];
    const V l = G.R0[k].transpose() * (p0 + r[k] - G.b[k]);
    const S rho = sqrt(l.dot(l));
    const V sk = l / rho;
    const S sb = sk[0], cb = sqrt(sk[1] * sk[1] + sk[2] * sk[2]), sa = -sk[1] / cb, ca = sk[2] / cb;
    q[7 + 5 * k] = ca; q[8 + 5 * k] = sa; q[9 + 5 * k] = cb; q[10 + 5 * k] = sb; q[11 + 5 * k] = rho - G.tip[k];
    ea[k] = V(S(0), -ca * cb, -sa * cb); eb[k] = V(cb, sa * sb, -ca * sb); sv[k] = sk;
    const V ld = G.R0[k].transpose() * (vel + w.cross(r[k]));
    const V ldd = G.R0[k].transpose() * (vd + wd.cross(r[k]) + w.cross(w.cross(r[k])));
    const S ka = one / (rho * cb * cb), kb = one / rho;
    const S ad = ka * ea[k].dot(ld), bd = kb * eb[k].dot(ld), dd = sk.dot(ld);
    const V Saa(S(0), sa * cb, -ca * cb), Sab(S(0), ca * sb, sa * sb), Sbb(-sb, sa * cb, -ca * cb);
    const V drift = two * dd * (ad * ea[k] + bd * eb[k]) + rho * (ad * ad * Saa + two * ad * bd * Sab + bd * bd * Sbb);
    const V rr = ldd - drift;
    v[6 + 3 * k] = ad; v[7 + 3 * k] = bd; v[8 + 3 * k] = dd;
    a[6 + 3 * k] = ka * ea[k].dot(rr); a[7 + 3 * k] = kb * eb[k].dot(rr); a[8 + 3 * k] = sk.dot(rr);
    ea[k] *= ka; eb[k] *= kb;
  }
  rnea(m, d, q, v, a);
  // [force; moment] rows of f and of Aᵀ.
  Eigen::Matrix<S, 6, 1> f;
  Eigen::Matrix<S, 6, 6> At;
  const V ff = R * d.tau.template head<3>(), nf = R * d.tau.template segment<3>(3);
  for (int i = 0; i < 3; ++i) { f[i] = ff[i]; f[3 + i] = nf[i]; }
  for (int k = 0; k < 6; ++k) {
    const V tl = d.tau[6 + 3 * k] * ea[k] + d.tau[7 + 3 * k] * eb[k] + d.tau[8 + 3 * k] * sv[k];
    const V wk = G.R0[k] * tl, g = G.R0[k] * sv[k], rg = r[k].cross(g), rw = r[k].cross(wk);
    for (int i = 0; i < 3; ++i) { f[i] += wk[i]; f[3 + i] += rw[i]; At(i, k) = g[i]; At(3 + i, k) = rg[i]; }
  }
  for (int c = 0; c < 6; ++c) {
    const S inv = one / At(c, c);
    for (int i = c + 1; i < 6; ++i) {
      const S l = At(i, c) * inv;
      for (int j = c + 1; j < 6; ++j) At(i, j) -= l * At(c, j);
      f[i] -= l * f[c];
    }
  }
  Eigen::Matrix<S, 6, 1> t;
  for (int c = 5; c >= 0; --c) {
    S acc = f[c];
    for (int j = c + 1; j < 6; ++j) acc -= At(c, j) * t[j];
    t[c] = acc / At(c, c);
  }
  return t;
}

// Route "pinocchio-cg-whole": forces_t taped on Pinocchio's AD model and compiled by CppADCodeGen
// (Pinocchio's CodeGenBase, as its CodeGenRNEA is built): one generated C function (x, u, ud) -> f.
struct CgWhole : pinocchio::CodeGenBase<double> {
  using Base = pinocchio::CodeGenBase<double>;
  LegsT<ADScalar> Gad;
  Eigen::VectorXd in = Eigen::VectorXd::Zero(19);  // dynamic: GenericModel::ForwardZero takes VectorXd
  double seconds = 0;
  CgWhole(const Model &m, const Legs &G) : Base(m, 19, 6, "gs_forces", "cg_gs_forces"), Gad(G) {
    ad_q = ADConfigVectorType(m.nq); ad_v = ADTangentVectorType(m.nv); ad_a = ADTangentVectorType(m.nv);
  }
  void buildMap() override {
    CppAD::Independent(ad_X);
    ad_Y = forces_t<ADScalar>(ad_model, ad_data, Gad, ad_X, ad_q, ad_v, ad_a);
    ad_fun.Dependent(ad_X, ad_Y);
    ad_fun.optimize("no_compare_op");
  }
  void build(const std::vector<std::string> &flags) {
    auto t0 = std::chrono::steady_clock::now();
    build_jacobian = false;
    initLib();
    if (!existLib()) {
      CppAD::cg::GccCompiler<double> gcc("/usr/bin/gcc");
      gcc.setCompileFlags(flags);
      std::vector<std::string> lib = flags;
      lib.push_back("-shared");
      lib.push_back("-rdynamic");
      gcc.setCompileLibFlags(lib);
      dynamicLibManager_ptr->createDynamicLibrary(gcc, false);
    }
    loadLib(false);
    seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  V6 operator()(const State &s) {
    for (int i = 0; i < 7; ++i) in[i] = s.x[i];
    for (int i = 0; i < 6; ++i) { in[7 + i] = s.u[i]; in[13 + i] = s.ud[i]; }
    evalFunction(in);
    return y;
  }
};

static std::vector<State> read(const std::string &path) {
  std::vector<State> out;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream is(line);
    State s;
    double *f[] = {s.x, s.u, s.ud, s.q, s.tau};
    int n[] = {7, 6, 6, 6, 6};
    for (int i = 0; i < 5; ++i)
      for (int j = 0; j < n[i]; ++j) { std::string t; is >> t; f[i][j] = std::strtod(t.c_str(), nullptr); }
    out.push_back(s);
  }
  return out;
}

static double rel(const V6 &a, const double *b) {
  double m = 0, e = 0;
  for (int i = 0; i < 6; ++i) { m = std::max(m, std::abs(b[i])); e = std::max(e, std::abs(a[i] - b[i])); }
  return e / std::max(m, 1e-300);
}

static double cpu_ns() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return 1e9 * t.tv_sec + t.tv_nsec;
}

// Median over 101 batches (each 2 passes over the states) of ns per call: wall-clock time and the
// thread's CPU time (the machine is shared: the CPU time leaves out the time other processes
// held the core).
struct Times { double wall, cpu; };
template <class F> static Times timed(const std::vector<State> &st, F f) {
  std::vector<double> tw, tc;
  double sink = 0;
  const int passes = 2;
  for (int b = 0; b < 101; ++b) {
    const double c0 = cpu_ns();
    auto t0 = std::chrono::steady_clock::now();
    for (int r = 0; r < passes; ++r)
      for (const State &s : st) sink += f(s)[0];
    auto t1 = std::chrono::steady_clock::now();
    const double c1 = cpu_ns();
    const double n = double(st.size() * passes);
    tw.push_back(std::chrono::duration<double, std::nano>(t1 - t0).count() / n);
    tc.push_back((c1 - c0) / n);
  }
  std::sort(tw.begin(), tw.end());
  std::sort(tc.begin(), tc.end());
  if (sink == 12345.678) std::cout << "";
  return {tw[50], tc[50]};
}

// Pinocchio's CodeGenRNEA (CppADCodeGen) of the opened tree, its C compiled with gcc FLAGS into
// LIBDIR (as ../bench_cg.cpp builds the arms' libraries).
struct CgRnea : pinocchio::CodeGenRNEA<double> {
  using pinocchio::CodeGenRNEA<double>::CodeGenRNEA;
  double seconds = 0;
  void build(const std::vector<std::string> &flags) {
    auto t0 = std::chrono::steady_clock::now();
    build_jacobian = false;  // the forward function only (what is timed)
    initLib();
    if (!existLib()) {
      CppAD::cg::GccCompiler<double> gcc("/usr/bin/gcc");
      gcc.setCompileFlags(flags);
      std::vector<std::string> lib = flags;
      lib.push_back("-shared");
      lib.push_back("-rdynamic");
      gcc.setCompileLibFlags(lib);
      dynamicLibManager_ptr->createDynamicLibrary(gcc, false);
    }
    loadLib(false);
    seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  // The library call on (q, v, a) packed into x: y = tau.
  const Eigen::VectorXd &operator()(const Work &W) {
    x.head(37) = W.q; x.segment(37, 24) = W.v; x.tail(24) = W.a;
    static_cast<pinocchio::CodeGenBase<double> &>(*this).evalFunction(x);
    return y;
  }
};

static int run(const char *name, const Spec &spec, const std::string &data, const std::vector<std::string> &flags,
               const std::filesystem::path &libdir) {
  const Model m = build(spec);
  const Legs G(spec);
  Work W(m);
  const std::vector<State> st = read(data);
  if (st.empty()) { std::cerr << data << ": no states\n"; return 1; }
  auto plain = [&](Work &w) -> const Eigen::VectorXd & { return rnea(w.m, w.d, w.q, w.v, w.a); };
  // CodeGenRNEA names its library cg_rnea_eval in the working directory: one directory per model.
  const auto home = std::filesystem::current_path();
  std::filesystem::create_directories(libdir / name);
  std::filesystem::current_path(libdir / name);
  CgRnea cg(m);
  cg.build(flags);
  CgWhole whole(m, G);
  whole.build(flags);
  std::filesystem::current_path(home);
  // Accuracy first: each route's forces against the generated ones; the IK's leg lengths too.
  double ejac = 0, eclosed = 0, ecg = 0, eq = 0, et = 0, ewhole = 0;
  const LegsT<double> Gd(G);
  for (const State &s : st) {
    Eigen::Matrix<double, 19, 1> in;
    for (int i = 0; i < 7; ++i) in[i] = s.x[i];
    for (int i = 0; i < 6; ++i) { in[7 + i] = s.u[i]; in[13 + i] = s.ud[i]; }
    et = std::max(et, rel(forces_t<double>(m, W.d, Gd, in, W.q, W.v, W.a), s.tau));
    ewhole = std::max(ewhole, rel(whole(s), s.tau));
    ejac = std::max(ejac, rel(route_jac(G, s, W), s.tau));
    ecg = std::max(ecg, rel(route_closed(G, s, W, cg), s.tau));
    eclosed = std::max(eclosed, rel(route_closed(G, s, W, plain), s.tau));
    for (int k = 0; k < 6; ++k) eq = std::max(eq, std::abs(W.q[11 + 5 * k] - s.q[k]));
  }
  const Times tjac = timed(st, [&](const State &s) { return route_jac(G, s, W); });
  const Times tclosed = timed(st, [&](const State &s) { return route_closed(G, s, W, plain); });
  const Times tcg = timed(st, [&](const State &s) { return route_closed(G, s, W, cg); });
  const Times trnea = timed(st, [&](const State &) { return V6(plain(W).head<6>()); });
  const Times twhole = timed(st, [&](const State &s) { return whole(s); });
  const Times tcgr = timed(st, [&](const State &) { return V6(cg(W).head<6>()); });
  std::printf("pin %s states %zu nq %d nv %d  errors: jac %.1e closed %.1e cg %.1e template %.1e cg-whole %.1e leg-lengths %.1e m  build s: cg %.1f cg-whole %.1f\n",
              name, st.size(), (int)m.nq, (int)m.nv, ejac, eclosed, ecg, et, ewhole, eq, cg.seconds, whole.seconds);
  std::printf("pin %s ns wall: jac %.1f closed %.1f cg %.1f cg-whole %.1f rnea %.1f cg-rnea %.1f  cpu: jac %.1f closed %.1f cg %.1f cg-whole %.1f rnea %.1f cg-rnea %.1f\n",
              name, tjac.wall, tclosed.wall, tcg.wall, twhole.wall, trnea.wall, tcgr.wall, tjac.cpu, tclosed.cpu, tcg.cpu, twhole.cpu, trnea.cpu, tcgr.cpu);
  if (!(ejac <= 1e-10 && eclosed <= 1e-10 && ecg <= 1e-10 && et <= 1e-10 && ewhole <= 1e-10)) {
    std::fprintf(stderr, "%s: a Pinocchio route disagrees with the generated forces (> 1e-10)\n", name);
    return 1;
  }
  return 0;
}

// Usage: gs_bench "GCC FLAGS" LIBDIR (reads data/bundled.txt and data/full.txt).
int main(int argc, char **argv) {
  if (argc < 3) { std::cerr << "usage: gs_bench \"GCC FLAGS\" LIBDIR\n"; return 2; }
  std::vector<std::string> flags;
  { std::istringstream in(argv[1]); std::string f; while (in >> f) flags.push_back(f); }
  const std::filesystem::path libdir = std::filesystem::absolute(argv[2]);
  int rc = 0;
  rc |= run("bundled", Spec{bundled::gravity, &bundled::platform, bundled::legs}, "data/bundled.txt", flags, libdir);
  rc |= run("full", Spec{full::gravity, &full::platform, full::legs}, "data/full.txt", flags, libdir);
  return rc;
}
