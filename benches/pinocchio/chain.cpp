// Times Pinocchio on the planar chain of hrm's benches: n revolute-z joints, uniform links of
// 0.1 m and 0.1 kg (centre of mass at the midpoint, inertia m L^2 / 12 about it), gravity
// 9.81 m/s^2 along -y, at a curled, moving state (benches/benches/derivatives.rs). For each size:
//   - aba: forward dynamics (beside hrm's `full_fd/n`);
//   - crba + nonLinearEffects + projection + LLT: reduced forward dynamics of m = 3 modal
//     coordinates the way a Pinocchio user would get it, M* = J^T M J, C* + G* = J^T nle, then
//     M*^-1 (tau* - C* - G*) (beside hrm's `reduced_fd/n`; the timing does not depend on J's
//     values, so J is a fixed dense n x 3 matrix);
//   - computeABADerivatives and computeRNEADerivatives (beside hrm's `aba_derivatives/n` and
//     `rnea_derivatives/n`).
// And on the spatial chains of hrm's spatial benches, read from the same URDF files
// (snake20.urdf: the 10-link universal-joint snake, 20 joints, massless crosses; random7.urdf: 7
// joints of pseudo-random axes and origins, one prismatic), gravity [0, 0, -9.81], at the state of
// benches/benches/spatial_dynamics.rs (`spatial_anchors`):
//   - aba one state (beside hrm's `spatial_aba/<name>`), aba over 1024 states one after another
//     (per state, beside `spatial_aba_batch/<name>`), computeABADerivatives (beside
//     `spatial_aba_derivatives/<name>`), computeRNEADerivatives at qdd = the state's tau, as
//     hrm's bench takes it (beside `spatial_rnea_derivatives/<name>`).
// Prints one line per algorithm and size, `pinocchio/<algorithm>/<n> <median> ns`: the median
// over batches of the time per call (the figures `cargo xtask bench --check` reads; the ids name
// the hrm bench each one stands beside).
//
// Build and run with ./run.sh (it compiles against the headers and library of the `pin` wheel).

#include <pinocchio/algorithm/aba-derivatives.hpp>
#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/algorithm/rnea-derivatives.hpp>
#include <pinocchio/multibody.hpp>
#include <pinocchio/parsers/urdf.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

using namespace pinocchio;

static Model planar_chain(int n, double length, double mass) {
  Model model;
  model.gravity.linear(Eigen::Vector3d(0.0, -9.81, 0.0));
  JointIndex parent = 0;
  for (int i = 0; i < n; ++i) {
    // Joint i sits at the far end of link i - 1 (at the origin for the base joint).
    SE3 placement = SE3::Identity();
    if (i > 0) placement.translation() = Eigen::Vector3d(length, 0.0, 0.0);
    parent = model.addJoint(parent, JointModelRZ(), placement, "joint" + std::to_string(i));
    Eigen::Matrix3d rotational = Eigen::Matrix3d::Zero();
    // A thin beam along x: only the z axis matters in the plane.
    rotational(2, 2) = mass * length * length / 12.0;
    rotational(1, 1) = rotational(2, 2);
    rotational(0, 0) = 1e-9;
    model.appendBodyToJoint(parent, Inertia(mass, Eigen::Vector3d(0.5 * length, 0.0, 0.0), rotational));
  }
  return model;
}

template <typename F>
static double median_ns(F&& call, int calls_per_batch, int batches) {
  std::vector<double> times;
  for (int b = 0; b < batches; ++b) {
    auto start = std::chrono::steady_clock::now();
    for (int i = 0; i < calls_per_batch; ++i) call();
    auto stop = std::chrono::steady_clock::now();
    times.push_back(std::chrono::duration<double, std::nano>(stop - start).count() / calls_per_batch);
  }
  std::sort(times.begin(), times.end());
  return times[times.size() / 2];
}

// The spatial anchors: Pinocchio on hrm's spatial bench chains, read from `dir`'s URDF files.
static void spatial_anchors(const std::string& dir) {
  const int batch = 1024;
  for (const char* name : {"snake20", "random7"}) {
    Model model;
    pinocchio::urdf::buildModel(dir + "/" + name + ".urdf", model);
    model.gravity.linear(Eigen::Vector3d(0.0, 0.0, -9.81));
    Data data(model);
    const int n = model.nv;
    Eigen::VectorXd q(n), v(n), tau(n);
    for (int i = 0; i < n; ++i) {
      auto s = [&](double k) { return std::sin(k * i / n + 0.3); };
      q[i] = 0.3 * s(6.0);
      v[i] = 0.5 * s(3.0);
      tau[i] = 0.01 * s(2.0);
    }
    double one_ns = median_ns([&] { aba(model, data, q, v, tau); }, 20000, 51);
    // 1024 states spread as in hrm's batch bench: state k is the state above times 1 + 1e-3 k.
    Eigen::MatrixXd qs(n, batch), vs(n, batch), taus(n, batch), out(n, batch);
    for (int k = 0; k < batch; ++k) {
      double factor = 1.0 + 1e-3 * k;
      qs.col(k) = q * factor;
      vs.col(k) = v * factor;
      taus.col(k) = tau * factor;
    }
    double batch_ns = median_ns(
        [&] {
          for (int k = 0; k < batch; ++k) out.col(k) = aba(model, data, qs.col(k), vs.col(k), taus.col(k));
        },
        20, 51) / batch;
    double derivatives_ns = median_ns([&] { computeABADerivatives(model, data, q, v, tau); }, 5000, 51);
    const double minv00 = data.Minv(0, 0);
    double rnea_ns = median_ns([&] { computeRNEADerivatives(model, data, q, v, tau); }, 5000, 51);
    std::printf("pinocchio/spatial_aba/%s %.1f ns\n", name, one_ns);
    std::printf("pinocchio/spatial_aba_batch/%s %.1f ns\n", name, batch_ns);
    std::printf("pinocchio/spatial_aba_derivatives/%s %.1f ns\n", name, derivatives_ns);
    std::printf("pinocchio/spatial_rnea_derivatives/%s %.1f ns\n", name, rnea_ns);
    std::printf("  check: qdd[n-1] = %.12g, dqdd/dtau[0][0] = %.12g, dtau/dq[0][0] = %.12g\n", data.ddq[n - 1],
                minv00, data.dtau_dq(0, 0));
  }
}

int main(int argc, char** argv) {
  for (int n : {10, 100}) {
    Model model = planar_chain(n, 0.1, 0.1);
    Data data(model);
    Eigen::VectorXd q(n), v(n), tau(n);
    for (int i = 0; i < n; ++i) {
      double x = double(i) / n;
      q[i] = 0.3 * std::sin(6.0 * x);
      v[i] = 0.5 * std::sin(3.0 * x);
      tau[i] = 0.01 * std::sin(2.0 * x);
    }
    int calls = n <= 10 ? 20000 : 500;
    double fd_ns = median_ns([&] { aba(model, data, q, v, tau); }, calls, 51);
    Eigen::MatrixXd jacobian(n, 3);
    for (int i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k) jacobian(i, k) = std::cos(0.7 * (k + 1) * (i + 1) / n);
    Eigen::Vector3d tau_star(1.0, -0.5, 0.2), a_ddot;
    double reduced_ns = median_ns(
        [&] {
          crba(model, data, q);
          data.M.triangularView<Eigen::StrictlyLower>() = data.M.transpose().triangularView<Eigen::StrictlyLower>();
          nonLinearEffects(model, data, q, v);
          Eigen::Matrix3d reduced_mass = jacobian.transpose() * data.M * jacobian;
          Eigen::Vector3d bias = jacobian.transpose() * data.nle;
          a_ddot = reduced_mass.llt().solve(tau_star - bias);
        },
        calls, 51);
    std::printf("pinocchio/aba/%d %.1f ns\n", n, fd_ns);
    // crba + nonLinearEffects + J^T M J, J^T nle + 3x3 LLT
    std::printf("pinocchio/reduced_fd/%d %.1f ns\n", n, reduced_ns);
    double aba_ns = median_ns([&] { computeABADerivatives(model, data, q, v, tau); }, calls, 51);
    // The qdd that ABA finds, for RNEA's derivatives at the same state.
    Eigen::VectorXd a = data.ddq;
    double rnea_ns = median_ns([&] { computeRNEADerivatives(model, data, q, v, a); }, calls, 51);
    std::printf("pinocchio/aba_derivatives/%d %.1f ns\n", n, aba_ns);
    std::printf("pinocchio/rnea_derivatives/%d %.1f ns\n", n, rnea_ns);
    // A check that the harness times the same chain: the acceleration of the last joint.
    std::printf("  check: qdd[n-1] = %.12g, dqdd/dtau[0][0] = %.12g\n", data.ddq[n - 1],
                data.Minv(0, 0));
  }
  // The folder of the URDF files (run.sh passes benches/pinocchio).
  if (argc > 1) spatial_anchors(argv[1]);
  return 0;
}
