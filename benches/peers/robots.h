// Shared by robots.cpp and kinematics.cpp: Pinocchio's model of a URDF as
// written (fixed base, locked joints held at zero, mimic joints as asked),
// and the map from our coordinates to its q and v by joint NAME (every one
// of ours must be a one-degree-of-freedom joint of Pinocchio's, and
// Pinocchio's model must have no other), so that an order that differs, a
// joint one side moves and the other does not, or a count that differs is
// an error rather than a silently permuted comparison. A continuous joint,
// one angle on our side, is (cos, sin) in Pinocchio's q.
#ifndef PEERS_ROBOTS_H
#define PEERS_ROBOTS_H

#include <pinocchio/algorithm/joint-configuration.hpp>
#include <pinocchio/algorithm/model.hpp>
#include <pinocchio/multibody.hpp>
#include <pinocchio/parsers/urdf.hpp>

#include <cstdio>
#include <string>
#include <vector>

namespace pin = pinocchio;

// The model of a URDF as written (fixed base), with the joints named in
// `locked` held at zero, mimic joints following theirs if `mimic`.
static pin::Model load(const std::string &path, const std::vector<std::string> &locked,
                       bool mimic) {
  pin::Model full;
  pin::urdf::buildModel(path, full, false, mimic);
  std::vector<pin::JointIndex> ids;
  for (const std::string &name : locked) {
    if (!full.existJointName(name)) {
      fprintf(stderr, "%s has no joint %s\n", path.c_str(), name.c_str());
      exit(2);
    }
    ids.push_back(full.getJointId(name));
  }
  if (ids.empty()) return full;
  Eigen::VectorXd zero = pin::neutral(full);
  for (pin::JointIndex id : ids) {
    const auto &j = full.joints[id];
    if (j.nq() != 1) {
      fprintf(stderr, "%s: locked joint %s has %d coordinates\n", path.c_str(),
              full.names[id].c_str(), j.nq());
      exit(2);
    }
    zero[j.idx_q()] = 0;
  }
  return pin::buildReducedModel(full, ids, zero);
}

static bool is_mimic(const pin::Model &model, pin::JointIndex id) {
  return model.joints[id].shortname() == "JointModelMimic";
}

// Where each of our coordinates is in Pinocchio's q and v, by name.
struct Map {
  std::vector<int> iq, nq, iv;
};

// The map of `names` (our COORDINATES, n of them) into `model`; `robot`
// names the robot in messages.
static Map match(const pin::Model &model, const std::string &robot,
                 const std::vector<std::string> &names, int n) {
  Map map;
  for (const std::string &name : names) {
    if (!model.existJointName(name)) {
      fprintf(stderr, "%s: Pinocchio's model has no joint %s\n", robot.c_str(), name.c_str());
      exit(2);
    }
    const pin::JointIndex id = model.getJointId(name);
    const auto &j = model.joints[id];
    if (is_mimic(model, id) || j.nv() != 1 || (j.nq() != 1 && j.nq() != 2)) {
      fprintf(stderr, "%s: %s is not one coordinate in Pinocchio's model (%s, nq %d, nv %d)\n",
              robot.c_str(), name.c_str(), j.shortname().c_str(), j.nq(), j.nv());
      exit(2);
    }
    map.iq.push_back(j.idx_q());
    map.nq.push_back(j.nq());
    map.iv.push_back(j.idx_v());
  }
  int moving = 0;
  for (pin::JointIndex id = 1; id < (pin::JointIndex)model.njoints; id++)
    if (!is_mimic(model, id)) moving++;
  if (moving != (int)names.size() || model.nv != n) {
    fprintf(stderr, "%s: Pinocchio's model moves %d joints (nv %d), ours %zu\n", robot.c_str(),
            moving, model.nv, names.size());
    exit(2);
  }
  return map;
}

// Our angles in Pinocchio's q.
static Eigen::VectorXd pinocchio_q(const pin::Model &model, const Map &map,
                                   const Eigen::VectorXd &q) {
  Eigen::VectorXd p = Eigen::VectorXd::Zero(model.nq);
  for (size_t i = 0; i < map.iq.size(); i++) {
    if (map.nq[i] == 2) {
      p[map.iq[i]] = cos(q[i]);
      p[map.iq[i] + 1] = sin(q[i]);
    } else {
      p[map.iq[i]] = q[i];
    }
  }
  return p;
}

// A vector of ours in Pinocchio's v order.
static Eigen::VectorXd pinocchio_v(const pin::Model &model, const Map &map,
                                   const Eigen::VectorXd &x) {
  Eigen::VectorXd p = Eigen::VectorXd::Zero(model.nv);
  for (size_t i = 0; i < map.iv.size(); i++) p[map.iv[i]] = x[i];
  return p;
}

// Pinocchio's vector / matrix (rows and columns by v) in our order.
static Eigen::VectorXd ours(const Map &map, const Eigen::VectorXd &x) {
  Eigen::VectorXd out(map.iv.size());
  for (size_t i = 0; i < map.iv.size(); i++) out[i] = x[map.iv[i]];
  return out;
}

static Eigen::MatrixXd ours(const Map &map, const Eigen::MatrixXd &x) {
  const int n = map.iv.size();
  Eigen::MatrixXd out(n, n);
  for (int i = 0; i < n; i++)
    for (int j = 0; j < n; j++) out(i, j) = x(map.iv[i], map.iv[j]);
  return out;
}

// Pinocchio's matrix with columns by v (rows as they are) in our order.
static Eigen::MatrixXd our_columns(const Map &map, const Eigen::MatrixXd &x) {
  Eigen::MatrixXd out(x.rows(), map.iv.size());
  for (size_t j = 0; j < map.iv.size(); j++) out.col(j) = x.col(map.iv[j]);
  return out;
}

// The largest difference relative to the largest entry of ours.
static double relative(const Eigen::MatrixXd &pinocchio, const Eigen::MatrixXd &generated) {
  return (pinocchio - generated).lpNorm<Eigen::Infinity>() / generated.lpNorm<Eigen::Infinity>();
}

#endif
