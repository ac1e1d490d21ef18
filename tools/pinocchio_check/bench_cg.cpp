// Pinocchio's code-generated dynamics (CppADCodeGen, pinocchio/codegen/cppadcg-algo.hpp) beside
// plain Pinocchio, on the arms' URDFs (README.md, "Against Pinocchio's code generation").
//
// For each URDF given: Pinocchio's CodeGenRNEA, CodeGenCRBA, CodeGenRNEADerivatives and
// CodeGenABADerivatives tape Pinocchio's algorithm with CppAD, CppADCodeGen writes C source and
// gcc compiles it into a shared library (flags: argv[1], split at spaces), which is loaded with
// dlopen. Each generated function is checked once against plain Pinocchio at 5 states (the
// program fails on a relative error above 1e-9), then timed as bench.cpp times plain Pinocchio:
// 256 random states, median of 31 batches, ns per call. Plain Pinocchio is timed in the same
// run. Two times per generated function: "cg" is the CodeGen class's evalFunction(q, v, a) as
// Pinocchio's own benchmark/timings-cg.cpp calls it (packs the input vector, calls the library,
// copies the outputs into its matrices); "raw" is the library call alone on a packed input.
//
// Usage: pinocchio_bench_cg "GCC FLAGS" LIBDIR URDF...  (the libraries are built in
// LIBDIR/NAME/; an existing library is loaded as is, not rebuilt).
#include <pinocchio/codegen/cppadcg.hpp>  // before the other Pinocchio headers
#include <pinocchio/codegen/cppadcg-algo.hpp>
#include <pinocchio/parsers/urdf.hpp>
#include <pinocchio/algorithm/joint-configuration.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/rnea-derivatives.hpp>
#include <pinocchio/algorithm/aba-derivatives.hpp>
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

using VectorXs = Eigen::VectorXd;
using RowMatrixXs = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// A CodeGen class whose library is compiled with the given gcc flags (CodeGenBase::compileLib
// takes one flag only) and whose raw input/output vectors are reachable.
template<class CG>
struct Native : CG {
  using CG::CG;
  double seconds = 0;  // taping, source generation and compilation
  void build(const std::vector<std::string> & flags) {
    auto t0 = std::chrono::steady_clock::now();
    this->initLib();
    if (!this->existLib()) {
      CppAD::cg::GccCompiler<double> gcc("/usr/bin/gcc");
      gcc.setCompileFlags(flags);
      std::vector<std::string> lib = flags;
      lib.push_back("-shared");
      lib.push_back("-rdynamic");
      gcc.setCompileLibFlags(lib);
      this->dynamicLibManager_ptr->createDynamicLibrary(gcc, false);
    }
    this->loadLib(false);
    seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  // The library call alone: y = f(x).
  void raw(const VectorXs & x) { static_cast<pinocchio::CodeGenBase<double> &>(*this).evalFunction(x); }
  const VectorXs & out() const { return this->y; }
};

// max |a - b| / max |b|
static double rel(const Eigen::Ref<const RowMatrixXs> & a, const Eigen::Ref<const RowMatrixXs> & b) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(b.cwiseAbs().maxCoeff(), 1e-300);
}

int main(int argc, char ** argv) {
  if (argc < 4) { std::cerr << "usage: pinocchio_bench_cg \"GCC FLAGS\" LIBDIR URDF...\n"; return 2; }
  std::vector<std::string> flags;
  { std::istringstream in(argv[1]); std::string f; while (in >> f) flags.push_back(f); }
  const std::filesystem::path libdir = std::filesystem::absolute(argv[2]);
  const auto home = std::filesystem::current_path();
  bool ok = true;
  for (int a = 3; a < argc; ++a) {
    const std::string name = std::filesystem::path(argv[a]).stem().string();
    pinocchio::Model m; pinocchio::urdf::buildModel(argv[a], m); pinocchio::Data d(m);
    const int nq = m.nq, nv = m.nv;
    // The states, as bench.cpp draws them.
    const int S = 256; std::mt19937 g(1); std::uniform_real_distribution<double> u(-1.5, 1.5);
    std::vector<VectorXs> q(S), v(S), acc(S), tau(S), xa(S), xq(S), xt(S);
    for (int s = 0; s < S; ++s) {
      q[s] = pinocchio::randomConfiguration(m, -VectorXs::Ones(nq) * 1.5, VectorXs::Ones(nq) * 1.5);
      v[s] = VectorXs::NullaryExpr(nv, [&]() { return u(g); });
      acc[s] = VectorXs::NullaryExpr(nv, [&]() { return u(g); });
      tau[s] = VectorXs::NullaryExpr(nv, [&]() { return 10 * u(g); });
      xa[s].resize(nq + 2 * nv); xa[s] << q[s], v[s], acc[s];  // packed (q, v, a)
      xt[s].resize(nq + 2 * nv); xt[s] << q[s], v[s], tau[s];  // packed (q, v, tau)
      xq[s] = q[s];
    }
    // Generate, compile and load (in LIBDIR/NAME: the library's file name has the model's name).
    std::filesystem::create_directories(libdir / name);
    std::filesystem::current_path(libdir / name);
    Native<pinocchio::CodeGenRNEA<double>> cg_rnea(m);
    Native<pinocchio::CodeGenCRBA<double>> cg_crba(m);
    Native<pinocchio::CodeGenRNEADerivatives<double>> cg_drnea(m);
    Native<pinocchio::CodeGenABADerivatives<double>> cg_daba(m);
    cg_rnea.build(flags); cg_crba.build(flags); cg_drnea.build(flags); cg_daba.build(flags);
    std::filesystem::current_path(home);

    // Check at 5 states against plain Pinocchio. CodeGenCRBA returns M's upper triangle, row by
    // row (nv(nv+1)/2 values); the derivatives' outputs are three row-major nv x nv blocks
    // (dtau_dq, dtau_dv, dtau_da = M; ddq_dq, ddq_dv, Minv), Pinocchio filling only the upper
    // triangle of the third: the first two blocks and that upper triangle are compared.
    double e[4] = {0, 0, 0, 0};
    for (int s = 0; s < 5; ++s) {
      cg_rnea.raw(xa[s]);
      e[0] = std::max(e[0], rel(cg_rnea.out().transpose(), pinocchio::rnea(m, d, q[s], v[s], acc[s]).transpose()));
      cg_crba.raw(xq[s]);
      pinocchio::crba(m, d, q[s]);
      VectorXs up(nv * (nv + 1) / 2); int k = 0;
      for (int i = 0; i < nv; ++i) for (int j = i; j < nv; ++j) up[k++] = d.M(i, j);
      e[1] = std::max(e[1], rel(cg_crba.out().transpose(), up.transpose()));
      cg_drnea.raw(xa[s]);
      pinocchio::computeRNEADerivatives(m, d, q[s], v[s], acc[s]);
      RowMatrixXs ref(2 * nv, nv); ref << d.dtau_dq, d.dtau_dv;
      e[2] = std::max(e[2], rel(Eigen::Map<const RowMatrixXs>(cg_drnea.out().data(), 2 * nv, nv), ref));
      cg_daba.raw(xt[s]);
      pinocchio::computeABADerivatives(m, d, q[s], v[s], tau[s]);
      RowMatrixXs ref2(2 * nv, nv); ref2 << d.ddq_dq, d.ddq_dv;
      e[3] = std::max(e[3], rel(Eigen::Map<const RowMatrixXs>(cg_daba.out().data(), 2 * nv, nv), ref2));
      RowMatrixXs mi = Eigen::Map<const RowMatrixXs>(cg_daba.out().data() + 2 * nv * nv, nv, nv).triangularView<Eigen::Upper>();
      RowMatrixXs mr = d.Minv.triangularView<Eigen::Upper>();
      e[3] = std::max(e[3], rel(mi, mr));
    }
    for (double x : e) if (!(x <= 1e-9)) ok = false;

    auto run = [&](auto f) { std::vector<double> t; double sink = 0;
      for (int b = 0; b < 31; ++b) { auto t0 = std::chrono::steady_clock::now(); for (int s = 0; s < S; ++s) sink += f(s); auto t1 = std::chrono::steady_clock::now(); t.push_back(std::chrono::duration<double, std::nano>(t1 - t0).count() / S); }
      std::sort(t.begin(), t.end()); if (sink == 12345.678) std::cout << ""; return t[15]; };
    // Plain Pinocchio (header-only, this program's flags).
    double p_rnea = run([&](int s) { return pinocchio::rnea(m, d, q[s], v[s], acc[s])[0]; });
    double p_crba = run([&](int s) { return pinocchio::crba(m, d, q[s])(0, 0); });
    double p_drnea = run([&](int s) { pinocchio::computeRNEADerivatives(m, d, q[s], v[s], acc[s]); return d.dtau_dq(0, 0) + d.dtau_dv(nv - 1, nv - 1); });
    double p_daba = run([&](int s) { pinocchio::computeABADerivatives(m, d, q[s], v[s], tau[s]); return d.ddq_dq(0, 0) + d.ddq_dv(nv - 1, nv - 1) + d.Minv(0, 0); });
    // Code-generated, through the CodeGen classes (as timings-cg.cpp) ...
    double c_rnea = run([&](int s) { cg_rnea.evalFunction(q[s], v[s], acc[s]); return cg_rnea.out()[0]; });
    double c_crba = run([&](int s) { cg_crba.evalFunction(q[s]); return cg_crba.M(0, 0); });
    double c_drnea = run([&](int s) { cg_drnea.evalFunction(q[s], v[s], acc[s]); return cg_drnea.out()[0]; });
    double c_daba = run([&](int s) { cg_daba.evalFunction(q[s], v[s], tau[s]); return cg_daba.out()[0]; });
    // ... and the library call alone on the packed input.
    double r_rnea = run([&](int s) { cg_rnea.raw(xa[s]); return cg_rnea.out()[0]; });
    double r_crba = run([&](int s) { cg_crba.raw(xq[s]); return cg_crba.out()[0]; });
    double r_drnea = run([&](int s) { cg_drnea.raw(xa[s]); return cg_drnea.out()[0]; });
    double r_daba = run([&](int s) { cg_daba.raw(xt[s]); return cg_daba.out()[0]; });
    std::cout << "cg " << name << " nv " << nv << " check: ID " << e[0] << " M " << e[1] << " dRNEA " << e[2]
              << " dABA " << e[3] << " build_s " << cg_rnea.seconds << " " << cg_crba.seconds << " " << cg_drnea.seconds
              << " " << cg_daba.seconds << " ns: plain " << p_rnea << " " << p_crba << " " << p_drnea << " " << p_daba
              << " cg " << c_rnea << " " << c_crba << " " << c_drnea << " " << c_daba
              << " raw " << r_rnea << " " << r_crba << " " << r_drnea << " " << r_daba << std::endl;
  }
  if (!ok) { std::cerr << "bench_cg: a code-generated function disagrees with Pinocchio (error above 1e-9)\n"; return 1; }
}
