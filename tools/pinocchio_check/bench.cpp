#include <pinocchio/parsers/urdf.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/rnea-derivatives.hpp>
#include <pinocchio/algorithm/aba-derivatives.hpp>
#include <chrono>
#include <iostream>
#include <random>
#include <vector>
#include <algorithm>
int main(int argc, char** argv) {
  for (int a = 1; a < argc; ++a) {
    pinocchio::Model m; pinocchio::urdf::buildModel(argv[a], m); pinocchio::Data d(m);
    const int S = 256; std::mt19937 g(1); std::uniform_real_distribution<double> u(-1.5, 1.5);
    std::vector<Eigen::VectorXd> q(S), v(S), acc(S);
    for (int s = 0; s < S; ++s) { q[s] = pinocchio::randomConfiguration(m, -Eigen::VectorXd::Ones(m.nq)*1.5, Eigen::VectorXd::Ones(m.nq)*1.5); v[s] = Eigen::VectorXd::NullaryExpr(m.nv, [&](){return u(g);}); acc[s] = Eigen::VectorXd::NullaryExpr(m.nv, [&](){return u(g);}); }
    auto run = [&](auto f) { std::vector<double> t; double sink = 0;
      for (int b = 0; b < 31; ++b) { auto t0 = std::chrono::steady_clock::now(); for (int s = 0; s < S; ++s) sink += f(s); auto t1 = std::chrono::steady_clock::now(); t.push_back(std::chrono::duration<double, std::nano>(t1 - t0).count() / S); }
      std::sort(t.begin(), t.end()); if (sink == 12345.678) std::cout << ""; return t[15]; };
    double trnea = run([&](int s){ return pinocchio::rnea(m, d, q[s], v[s], acc[s])[0]; });
    double tcrba = run([&](int s){ return pinocchio::crba(m, d, q[s])(0,0); });
    double taba = run([&](int s){ return pinocchio::aba(m, d, q[s], v[s], acc[s])[0]; });
    std::cout << argv[a] << " nv " << m.nv << " rnea " << trnea << " ns crba " << tcrba << " ns aba " << taba << " ns";
    if (m.nv <= 16) {  // the robots whose generated modules have the derivatives
      double trd = run([&](int s){ pinocchio::computeRNEADerivatives(m, d, q[s], v[s], acc[s]); return d.dtau_dq(0,0) + d.dtau_dv(m.nv-1,m.nv-1); });
      double tad = run([&](int s){ pinocchio::computeABADerivatives(m, d, q[s], v[s], acc[s]); return d.ddq_dq(0,0) + d.ddq_dv(m.nv-1,m.nv-1) + d.Minv(0,0); });
      std::cout << " computeRNEADerivatives " << trd << " ns computeABADerivatives " << tad << " ns";
    }
    std::cout << "\n";
  }
}
