// Times Pinocchio on the spatial modal arms of hrm's benches (`reduced_fd_spatial/<n>`): the
// URDF export of `hrm_benches::spatial_arm(n)` (n universal-joint links of 0.1 m and 0.1 kg as
// slender rods, 2n continuous joints in the order of hrm's theta, gravity 9.81 m/s^2 along -z,
// Pinocchio's default), with its modal map J (2n x 4) and the benches' state, both written by
// `cargo run -p hrm-benches --example spatial_urdf -- DIR` as DIR/spatial_<n>.{urdf,txt}.
//
// Reduced forward dynamics the way a Pinocchio user gets it: crba + nonLinearEffects at
// theta = J a, theta_dot = J a_dot, then M* = J^T M J, C* + G* = J^T nle and a 4x4 LLT solve of
// M* a_ddot = tau* - C* - G*. Prints `pinocchio/reduced_fd_spatial/<n> <median> ns` (the median
// over batches of the time per call, the figure `cargo xtask bench --check` reads) and, as a
// check that both time the same arm, the largest difference from hrm's a_ddot.
//
// Build and run with ./run.sh (it compiles against the headers and libraries of the `pin`
// wheel and writes the arms first).

#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/multibody.hpp>
#include <pinocchio/parsers/urdf.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

using namespace pinocchio;

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

static Eigen::VectorXd read_row(std::ifstream& in, int m) {
  Eigen::VectorXd row(m);
  for (int k = 0; k < m; ++k) in >> row[k];
  return row;
}

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: spatial <folder of spatial_<n>.urdf and .txt>\n");
    return 2;
  }
  const std::string folder = argv[1];
  for (int n : {10, 100}) {
    const std::string stem = folder + "/spatial_" + std::to_string(n);
    Model model;
    pinocchio::urdf::buildModel(stem + ".urdf", model);
    Data data(model);
    std::ifstream in(stem + ".txt");
    int joints = 0, m = 0;
    in >> joints >> m;
    if (!in || joints != model.nv || m != 4) {
      std::fprintf(stderr, "%s.txt: expected %d joints and 4 coordinates\n", stem.c_str(), int(model.nv));
      return 1;
    }
    Eigen::MatrixXd jacobian(joints, m);
    for (int j = 0; j < joints; ++j) jacobian.row(j) = read_row(in, m).transpose();
    const Eigen::Vector4d a = read_row(in, m), a_dot = read_row(in, m), tau_star = read_row(in, m),
                          hrm_a_ddot = read_row(in, m);
    if (!in) {
      std::fprintf(stderr, "%s.txt: short file\n", stem.c_str());
      return 1;
    }
    // Continuous joints are unbounded revolutes in Pinocchio: (cos, sin) in q, one rate in v.
    const Eigen::VectorXd theta = jacobian * a, v = jacobian * a_dot;
    Eigen::VectorXd q(model.nq);
    for (JointIndex j = 1; j < JointIndex(model.njoints); ++j) {
      const auto& joint = model.joints[j];
      const double angle = theta[joint.idx_v()];
      if (joint.nq() == 2) {
        q[joint.idx_q()] = std::cos(angle);
        q[joint.idx_q() + 1] = std::sin(angle);
      } else {
        q[joint.idx_q()] = angle;
      }
    }
    Eigen::Vector4d a_ddot;
    double reduced_ns = median_ns(
        [&] {
          crba(model, data, q);
          data.M.triangularView<Eigen::StrictlyLower>() = data.M.transpose().triangularView<Eigen::StrictlyLower>();
          nonLinearEffects(model, data, q, v);
          Eigen::Matrix4d reduced_mass = jacobian.transpose() * data.M * jacobian;
          Eigen::Vector4d bias = jacobian.transpose() * data.nle;
          a_ddot = reduced_mass.llt().solve(tau_star - bias);
        },
        n <= 10 ? 20000 : 200, 51);
    // crba + nonLinearEffects + J^T M J, J^T nle + 4x4 LLT
    std::printf("pinocchio/reduced_fd_spatial/%d %.1f ns\n", n, reduced_ns);
    std::printf("  check: |a_ddot - hrm's| = %.3g (|a_ddot| = %.3g)\n", (a_ddot - hrm_a_ddot).cwiseAbs().maxCoeff(),
                a_ddot.cwiseAbs().maxCoeff());
  }
  return 0;
}
