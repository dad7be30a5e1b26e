#include "calibration/heldout_dot_groups.h"

#include <Eigen/Cholesky>

namespace selfcal::calibration {

namespace {

int Root(std::map<int, int>* parent, int id) {
  while ((*parent)[id] != id) id = (*parent)[id] = (*parent)[(*parent)[id]];
  return id;
}

}  // namespace

std::vector<DotGroup> YardstickDotGroups(const std::vector<KnownDistance>& yardsticks, double sigma_m, double sigma_px,
                                         const std::map<int, Eigen::Matrix3d>& hdd,
                                         const std::map<int, Eigen::Vector3d>& dots) {
  std::vector<DotGroup> groups;
  if (!(sigma_m > 0) || !(sigma_px > 0)) return groups;
  std::vector<const KnownDistance*> used;
  std::map<int, int> parent;
  for (const KnownDistance& y : yardsticks) {
    if (y.dot_a == y.dot_b || hdd.count(y.dot_a) == 0 || hdd.count(y.dot_b) == 0 || dots.count(y.dot_a) == 0 ||
        dots.count(y.dot_b) == 0 || !((dots.at(y.dot_a) - dots.at(y.dot_b)).norm() > 0)) {
      continue;
    }
    used.push_back(&y);
    for (int id : {y.dot_a, y.dot_b}) parent.emplace(id, id);
    parent[Root(&parent, y.dot_a)] = Root(&parent, y.dot_b);
  }
  std::map<int, int> group_of_root, slot;
  for (auto& [id, p] : parent) {
    const int root = Root(&parent, id);
    if (group_of_root.count(root) == 0) {
      group_of_root[root] = static_cast<int>(groups.size());
      groups.emplace_back();
    }
    DotGroup& g = groups[group_of_root[root]];
    slot[id] = static_cast<int>(g.ids.size());
    g.ids.push_back(id);
  }
  std::vector<Eigen::MatrixXd> h(groups.size());
  for (size_t k = 0; k < groups.size(); ++k) {
    const int n = 3 * static_cast<int>(groups[k].ids.size());
    h[k] = Eigen::MatrixXd::Zero(n, n);
    for (size_t j = 0; j < groups[k].ids.size(); ++j) h[k].block<3, 3>(3 * j, 3 * j) = hdd.at(groups[k].ids[j]);
  }
  for (const KnownDistance* y : used) {
    Eigen::MatrixXd& g = h[group_of_root[Root(&parent, y->dot_a)]];
    const Eigen::Vector3d u = (dots.at(y->dot_a) - dots.at(y->dot_b)).normalized() * (sigma_px / sigma_m);
    const int a = 3 * slot[y->dot_a], b = 3 * slot[y->dot_b];
    g.block<3, 3>(a, a) += u * u.transpose();
    g.block<3, 3>(b, b) += u * u.transpose();
    g.block<3, 3>(a, b) -= u * u.transpose();
    g.block<3, 3>(b, a) -= u * u.transpose();
  }
  for (size_t k = 0; k < groups.size(); ++k) {
    groups[k].inverse = h[k].ldlt().solve(Eigen::MatrixXd::Identity(h[k].rows(), h[k].cols()));
  }
  return groups;
}

}  // namespace selfcal::calibration
