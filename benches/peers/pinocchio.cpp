// Pinocchio (C++, from the `pin` and `cmeel-eigen` wheels) on the systems of
// the reference file: the planar N-link chain with `aba`, and the four-bar
// with `constraintDynamics` and `lcaba`. Each answer is checked against the
// generated code's before it is timed; one JSON line per result.
//
// Usage: pinocchio REFERENCE_FILE
#include "common.h"

#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/constrained-dynamics.hpp>
#include <pinocchio/algorithm/loop-constrained-aba.hpp>
#include <pinocchio/multibody.hpp>

#include <string>
#include <vector>

namespace pin = pinocchio;
using Eigen::Matrix3d;
using Eigen::Vector3d;
using Eigen::VectorXd;

static VectorXd vec(const peer_record &r, const char *name) {
  int n = 0;
  const double *v = peer_get(&r, name, &n);
  return Eigen::Map<const VectorXd>(v, n);
}

// Point masses on massless rods, a revolute joint about z at the top of
// each rod; the rod hangs along −y at zero angle (the reference's absolute
// angles are measured from the downward vertical).
static pin::Model chain_model(const peer_record &r) {
  const int n = (int)r.head[0];
  const double g = r.head[1];
  const double *m = peer_get(&r, "masses", nullptr);
  const double *l = peer_get(&r, "lengths", nullptr);
  pin::Model model;
  model.gravity.linear(Vector3d(0, -g, 0));
  pin::JointIndex parent = 0;
  for (int i = 0; i < n; i++) {
    const pin::SE3 placement(Matrix3d::Identity(), Vector3d(0, i == 0 ? 0 : -l[i - 1], 0));
    parent = model.addJoint(parent, pin::JointModelRZ(), placement, "joint" + std::to_string(i));
    model.appendBodyToJoint(parent, pin::Inertia(m[i], Vector3d(0, -l[i], 0), Matrix3d::Zero()),
                            pin::SE3::Identity());
  }
  return model;
}

struct Aba {
  const pin::Model *model;
  pin::Data *data;
  VectorXd q, v, tau;
};

static void call_aba(void *p) {
  Aba *c = (Aba *)p;
  pin::aba(*c->model, *c->data, c->q, c->v, c->tau);
  PEER_KEEP(c->data->ddq.data());
}

typedef pin::RigidConstraintModel Rcm;
typedef pin::RigidConstraintData Rcd;
typedef std::vector<Rcm, Eigen::aligned_allocator<Rcm>> Rcms;
typedef std::vector<Rcd, Eigen::aligned_allocator<Rcd>> Rcds;

struct Loop {
  const pin::Model *model;
  pin::Data *data;
  const Rcms *models;
  Rcds *datas;
  pin::ProximalSettings settings;
  VectorXd q, v, tau;
  bool lcaba;
};

static void call_loop(void *p) {
  Loop *c = (Loop *)p;
  if (c->lcaba)
    pin::lcaba(*c->model, *c->data, c->q, c->v, c->tau, *c->models, *c->datas, c->settings);
  else
    pin::constraintDynamics(*c->model, *c->data, c->q, c->v, c->tau, *c->models, *c->datas,
                            c->settings);
  PEER_KEEP(c->data->ddq.data());
}

// The four-bar: crank about the origin, coupler pinned to the crank's tip
// (its angle relative to the crank), rocker about (d, 0); bars of mass m,
// moment of inertia jm about their centres. The coupler's far end is held
// to the rocker's tip by a point constraint (CONTACT_3D: its third row is
// zero in the plane, which the proximal solver's damping mu absorbs).
static void four_bar(const peer_record &r) {
  const double m = r.head[0], jm = r.head[1], l = r.head[2], d = r.head[3], g = r.head[4];
  pin::Model model;
  model.gravity.linear(Vector3d(0, -g, 0));
  const Matrix3d inertia = jm * Matrix3d::Identity();
  const pin::JointIndex crank =
      model.addJoint(0, pin::JointModelRZ(), pin::SE3::Identity(), "crank");
  model.appendBodyToJoint(crank, pin::Inertia(m, Vector3d(l / 2, 0, 0), inertia),
                          pin::SE3::Identity());
  const pin::JointIndex coupler = model.addJoint(
      crank, pin::JointModelRZ(), pin::SE3(Matrix3d::Identity(), Vector3d(l, 0, 0)), "coupler");
  model.appendBodyToJoint(coupler, pin::Inertia(m, Vector3d(d / 2, 0, 0), inertia),
                          pin::SE3::Identity());
  const pin::JointIndex rocker = model.addJoint(
      0, pin::JointModelRZ(), pin::SE3(Matrix3d::Identity(), Vector3d(d, 0, 0)), "rocker");
  model.appendBodyToJoint(rocker, pin::Inertia(m, Vector3d(l / 2, 0, 0), inertia),
                          pin::SE3::Identity());
  Rcms models;
  models.push_back(Rcm(pin::CONTACT_3D, model, coupler,
                       pin::SE3(Matrix3d::Identity(), Vector3d(d, 0, 0)), rocker,
                       pin::SE3(Matrix3d::Identity(), Vector3d(l, 0, 0)), pin::LOCAL));
  Rcds datas;
  for (const Rcm &cm : models) datas.push_back(Rcd(cm));
  const VectorXd expected = vec(r, "qdd");
  for (const bool lcaba : {false, true}) {
    pin::Data data(model);
    if (lcaba)
      pin::computeJointMinimalOrdering(model, data, models);
    else
      pin::initConstraintDynamics(model, data, models, datas);
    // Accuracy 1e-12 on the constraint residual, at most 100 proximal
    // iterations; damping mu 1e-10 for constraintDynamics (Pinocchio's
    // docs: "1e-12 when two contact constraints are redundant") and 1e-6
    // for lcaba (its docs' typical value; it needs mu > 0). lcaba's
    // iterations stop near 1e-9 of the exact answer, hence its tolerance.
    Loop c{&model,    &data, &models, &datas, pin::ProximalSettings(1e-12, lcaba ? 1e-6 : 1e-10, 100),
           vec(r, "q"), vec(r, "v"), VectorXd::Zero(model.nv), lcaba};
    call_loop(&c);
    const double difference = (data.ddq - expected).lpNorm<Eigen::Infinity>();
    peer_check_and_time("pinocchio", lcaba ? "lcaba" : "constraintDynamics", "four_bar", 3,
                        difference, lcaba ? 1e-8 : 1e-12, call_loop, &c);
  }
}

static void chain(const peer_record &r) {
  const pin::Model model = chain_model(r);
  pin::Data data(model);
  Aba c{&model, &data, vec(r, "q"), vec(r, "v"), VectorXd::Zero(model.nv)};
  call_aba(&c);
  const double difference = (data.ddq - vec(r, "qdd")).lpNorm<Eigen::Infinity>();
  peer_check_and_time("pinocchio", "aba", "chain", model.nv, difference, 1e-10, call_aba, &c);
}

int main(int argc, char **argv) {
  if (argc != 2) {
    fprintf(stderr, "usage: %s REFERENCE_FILE\n", argv[0]);
    return 2;
  }
  static peer_record records[16];
  const int n = peer_read(argv[1], records, 16);
  for (int i = 0; i < n; i++) {
    if (!strcmp(records[i].kind, "chain"))
      chain(records[i]);
    else
      four_bar(records[i]);
  }
  return peer_failures ? 1 : 0;
}
