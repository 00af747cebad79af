// Pinocchio (C++, from the `pin` wheel) against the generated kinematics
// and derivatives of the robots of the reference file written by
// benches/peers/robots (`kinematics write`: the Panda with a tool point on
// its hand, the Unitree G1 with a sole and a palm, the Unitree Go1 with a
// frame under each foot, each read from example-robot-data's URDF as
// written, fixed base). Each robot's model is built as robots.cpp builds
// it (robots.h: the same file, the same locked joints, matched to ours by
// joint NAME); each frame of the record (`frame NAME BODY x y z roll pitch
// yaw`: fixed in the URDF link BODY, at xyz turned by R = Rz(yaw) Ry(pitch)
// Rx(roll) in the link's frame) is added as an OP_FRAME on the link's BODY
// frame, its placement in the parent joint's frame being the link's (which
// carries the fixed joints that merged the link into its joint's body)
// times the record's.
//
// At every state of the file it checks, relative to the largest entry of
// the generated answer, to 1e-12 (QUANTITIES below, one row each):
//   frame_placement          forwardKinematics + updateFramePlacements: oMf
//                            (rotation and translation), every frame
//   frame_jacobian           computeFrameJacobian and computeJointJacobians
//                            + getFrameJacobian, LOCAL_WORLD_ALIGNED
//   frame_velocity           getFrameVelocity, LOCAL_WORLD_ALIGNED (answers only)
//   frame_acceleration_bias  getFrameClassicalAcceleration, LOCAL_WORLD_ALIGNED,
//                            after forwardKinematics(q, v, a = 0)
//   center_of_mass_and_jacobian  centerOfMass and jacobianCenterOfMass
//   center_of_mass_velocity  centerOfMass(q, v): vcom[0] (and com[0])
//   centroidal_map           computeCentroidalMap: Ag, rows [linear; angular]
//                            about the centre of mass, world axes
//   centroidal_map_bias      dccrba: dAg v (and Ag), and
//                            computeCentroidalMapTimeVariation's dAg v after it
//   centroidal_momentum_time_variation  computeCentroidalMomentumTimeVariation
//                            at a = 0: dhg, our centroidal_map_bias again,
//                            Pinocchio's cheaper way to the same vector
//   inverse_dynamics_jacobian  computeRNEADerivatives at the record's a:
//                            ∂τ/∂q, ∂τ/∂v
//   acceleration_jacobian    computeABADerivatives: ∂q̈/∂q, ∂q̈/∂v, ∂q̈/∂τ
//                            (its M⁻¹, symmetrised)
// with rows and columns by joint name (v is q̇ on these revolute joints, so
// a column per q̇ rate is a column per v: no free base here), and only if
// all of a robot's states agree does it time each against ours over the
// same states (the first frame; common.h's statistic on the thread's CPU
// clock, per state): forwardKinematics + updateFramePlacement,
// computeFrameJacobian, forwardKinematics(q, v, 0) +
// getFrameClassicalAcceleration, jacobianCenterOfMass (which computes the
// centre of mass too; without the subtrees' centres), centerOfMass(q, v)
// (without them too), computeCentroidalMap, dccrba (which computes Ag, hg
// and vcom as well) + dAg v,
// computeCentroidalMomentumTimeVariation(q, v, 0), computeRNEADerivatives
// (which computes ∂τ/∂a = M as well), computeABADerivatives. One JSON line
// per result, tagged with ROUND (run.sh alternates three rounds with ours).
// Adding a quantity is one entry of QUANTITIES here and one of
// `frame_times` or `whole_times` in
// benches/peers/robots/src/bin/kinematics.rs, with the lines its check
// reads written by `Write::state` there.
//
// Usage: kinematics ROBOTS_DIR REFERENCE_FILE ROUND
#include "common.h"
#include "robots.h"

#include <pinocchio/algorithm/aba-derivatives.hpp>
#include <pinocchio/algorithm/center-of-mass.hpp>
#include <pinocchio/algorithm/centroidal.hpp>
#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/jacobian.hpp>
#include <pinocchio/algorithm/kinematics.hpp>
#include <pinocchio/algorithm/rnea-derivatives.hpp>
#include <pinocchio/math.hpp>

#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

using Eigen::MatrixXd;
using Eigen::VectorXd;

// A frame of the record.
struct FrameSpec {
  std::string name, body;
  Eigen::Vector3d xyz, rpy;
};

// One state: every line of it by key (`q`, `jacobian:0`, ..), in our order.
typedef std::map<std::string, VectorXd> State;

// One robot's record.
struct Record {
  std::string name, urdf;
  int n = 0;
  std::vector<std::string> locked, names;
  std::vector<FrameSpec> frames;
  std::vector<State> states;
};

static std::vector<std::string> words(std::istringstream &in) {
  std::vector<std::string> out;
  std::string w;
  while (in >> w) out.push_back(w);
  return out;
}

static std::vector<Record> read(const char *path) {
  std::ifstream file(path);
  if (!file) {
    fprintf(stderr, "cannot open %s\n", path);
    exit(2);
  }
  std::vector<Record> out;
  std::string text;
  while (std::getline(file, text)) {
    std::istringstream in(text);
    std::string key;
    if (!(in >> key)) continue;
    if (key == "robot") {
      out.emplace_back();
      in >> out.back().name >> out.back().n;
      continue;
    }
    if (out.empty()) {
      fprintf(stderr, "%s: `%s` before any `robot`\n", path, key.c_str());
      exit(2);
    }
    Record &r = out.back();
    if (key == "urdf") in >> r.urdf;
    else if (key == "locked") r.locked = words(in);
    else if (key == "names") r.names = words(in);
    else if (key == "frame") {
      FrameSpec f;
      in >> f.name >> f.body >> f.xyz[0] >> f.xyz[1] >> f.xyz[2] >> f.rpy[0] >> f.rpy[1] >> f.rpy[2];
      if (in.fail()) {
        fprintf(stderr, "%s: a `frame` line short of its name, link and six numbers\n",
                r.name.c_str());
        exit(2);
      }
      r.frames.push_back(f);
    } else if (key == "state") r.states.emplace_back();
    else if (r.states.empty()) {
      fprintf(stderr, "%s: `%s` before any `state`\n", r.name.c_str(), key.c_str());
      exit(2);
    } else {
      std::vector<double> x;
      double d;
      while (in >> d) x.push_back(d);
      r.states.back()[key] = Eigen::Map<const VectorXd>(x.data(), x.size());
    }
  }
  return out;
}

// The line `key` of a state as a rows × cols matrix (written row by row).
static MatrixXd get(const Record &r, const State &s, const std::string &key, int rows,
                    int cols = 1) {
  const auto at = s.find(key);
  if (at == s.end() || at->second.size() != rows * cols) {
    fprintf(stderr, "%s: a state lacks `%s` of %d entries\n", r.name.c_str(), key.c_str(),
            rows * cols);
    exit(2);
  }
  return Eigen::Map<const Eigen::Matrix<double, -1, -1, Eigen::RowMajor>>(at->second.data(), rows,
                                                                          cols);
}

// Adds the record's frames to `model` as OP_FRAMEs; their indices.
static std::vector<pin::FrameIndex> add_frames(pin::Model &model, const Record &r) {
  std::vector<pin::FrameIndex> ids;
  for (const FrameSpec &f : r.frames) {
    if (!model.existFrame(f.body, pin::BODY)) {
      fprintf(stderr, "%s: Pinocchio's model has no link %s\n", r.name.c_str(), f.body.c_str());
      exit(2);
    }
    const pin::FrameIndex body = model.getFrameId(f.body, pin::BODY);
    const pin::Frame link = model.frames[body];
    const pin::SE3 local(pin::rpy::rpyToMatrix(f.rpy[0], f.rpy[1], f.rpy[2]), f.xyz);
    ids.push_back(model.addFrame(
        pin::Frame(f.name, link.parentJoint, body, link.placement * local, pin::OP_FRAME)));
  }
  return ids;
}

// A robot's model, its data, its states in Pinocchio's order and its
// frames: what the checks and the timed calls use.
struct Robot {
  const Record *record;
  pin::Model model;
  pin::Data *data;
  Map map;
  std::vector<VectorXd> q, v, tau, a;
  std::vector<pin::FrameIndex> frames;
  MatrixXd j, dq, dv, dtau;
  VectorXd zero;
};

static const pin::ReferenceFrame LWA = pin::LOCAL_WORLD_ALIGNED;

// The checks: the worst relative difference over the states (and frames).
static double check_placement(Robot &c) {
  double worst = 0;
  for (size_t k = 0; k < c.q.size(); k++) {
    pin::forwardKinematics(c.model, *c.data, c.q[k]);
    pin::updateFramePlacements(c.model, *c.data);
    for (size_t f = 0; f < c.frames.size(); f++) {
      const MatrixXd ours = get(*c.record, c.record->states[k], "placement:" + std::to_string(f), 1, 12);
      const pin::SE3 &o = c.data->oMf[c.frames[f]];
      const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> r = o.rotation();
      worst = fmax(worst, relative(Eigen::Map<const VectorXd>(r.data(), 9),
                                   ours.leftCols(9).transpose()));
      worst = fmax(worst, relative(o.translation(), ours.rightCols(3).transpose()));
    }
  }
  return worst;
}

static double check_jacobian(Robot &c) {
  double worst = 0;
  const int n = c.record->n;
  for (size_t k = 0; k < c.q.size(); k++) {
    pin::computeJointJacobians(c.model, *c.data, c.q[k]);
    for (size_t f = 0; f < c.frames.size(); f++) {
      const MatrixXd ours = get(*c.record, c.record->states[k], "jacobian:" + std::to_string(f), 6, n);
      MatrixXd j = MatrixXd::Zero(6, c.model.nv);
      pin::getFrameJacobian(c.model, *c.data, c.frames[f], LWA, j);
      worst = fmax(worst, relative(our_columns(c.map, j), ours));
      c.j.setZero();
      pin::computeFrameJacobian(c.model, *c.data, c.q[k], c.frames[f], LWA, c.j);
      worst = fmax(worst, relative(our_columns(c.map, c.j), ours));
    }
  }
  return worst;
}

// getFrameVelocity (which == 0) or getFrameClassicalAcceleration at q̈ = 0.
static double check_motion(Robot &c, int which) {
  double worst = 0;
  for (size_t k = 0; k < c.q.size(); k++) {
    pin::forwardKinematics(c.model, *c.data, c.q[k], c.v[k], c.zero);
    for (size_t f = 0; f < c.frames.size(); f++) {
      const std::string key = (which == 0 ? "velocity:" : "bias:") + std::to_string(f);
      const MatrixXd ours = get(*c.record, c.record->states[k], key, 6);
      const pin::Motion m =
          which == 0 ? pin::getFrameVelocity(c.model, *c.data, c.frames[f], LWA)
                     : pin::getFrameClassicalAcceleration(c.model, *c.data, c.frames[f], LWA);
      worst = fmax(worst, relative(m.toVector(), ours));
    }
  }
  return worst;
}

static double check_velocity(Robot &c) { return check_motion(c, 0); }
static double check_bias(Robot &c) { return check_motion(c, 1); }

static double check_com(Robot &c) {
  double worst = 0;
  for (size_t k = 0; k < c.q.size(); k++) {
    const State &s = c.record->states[k];
    const MatrixXd com = get(*c.record, s, "com", 3);
    const MatrixXd jcom = get(*c.record, s, "com_jacobian", 3, c.record->n);
    worst = fmax(worst, relative(pin::centerOfMass(c.model, *c.data, c.q[k]), com));
    pin::jacobianCenterOfMass(c.model, *c.data, c.q[k], false);
    worst = fmax(worst, relative(c.data->com[0], com));
    worst = fmax(worst, relative(our_columns(c.map, c.data->Jcom), jcom));
  }
  return worst;
}

static double check_aba_derivatives(Robot &c) {
  double worst = 0;
  const int n = c.record->n;
  for (size_t k = 0; k < c.q.size(); k++) {
    const State &s = c.record->states[k];
    pin::computeABADerivatives(c.model, *c.data, c.q[k], c.v[k], c.tau[k], c.dq, c.dv, c.dtau);
    MatrixXd minv = c.dtau;
    minv.triangularView<Eigen::StrictlyLower>() = minv.transpose();
    worst = fmax(worst, relative(ours(c.map, MatrixXd(c.dq)), get(*c.record, s, "dq", n, n)));
    worst = fmax(worst, relative(ours(c.map, MatrixXd(c.dv)), get(*c.record, s, "dv", n, n)));
    worst = fmax(worst, relative(ours(c.map, minv), get(*c.record, s, "dtau", n, n)));
  }
  return worst;
}

// centerOfMass(q, v): vcom[0] against `com_velocity` (and com[0]).
static double check_com_velocity(Robot &c) {
  double worst = 0;
  for (size_t k = 0; k < c.q.size(); k++) {
    const State &s = c.record->states[k];
    pin::centerOfMass(c.model, *c.data, c.q[k], c.v[k], false);
    worst = fmax(worst, relative(c.data->com[0], get(*c.record, s, "com", 3)));
    worst = fmax(worst, relative(c.data->vcom[0], get(*c.record, s, "com_velocity", 3)));
  }
  return worst;
}

static double check_centroidal_map(Robot &c) {
  double worst = 0;
  for (size_t k = 0; k < c.q.size(); k++) {
    const MatrixXd ours = get(*c.record, c.record->states[k], "centroidal_map", 6, c.record->n);
    pin::computeCentroidalMap(c.model, *c.data, c.q[k]);
    worst = fmax(worst, relative(our_columns(c.map, c.data->Ag), ours));
  }
  return worst;
}

// dccrba: its Ag against ours, dAg v against `centroidal_bias`; then
// computeCentroidalMapTimeVariation's dAg v too. The latter (Pinocchio
// 4.1's centroidal.hxx) reads data.vcom[0] without computing it, adding
// (m ċ) × vcom[0] to dAg v: right only when vcom[0] is this state's ċ (as
// dccrba, the same pass, has just left it) or zero. Called after another
// state's centerOfMass(q, v), it was off by 4e-2 to 4e-1 of the largest
// entry; hence dccrba is the row's counterpart.
static double check_centroidal_bias(Robot &c) {
  double worst = 0;
  for (size_t k = 0; k < c.q.size(); k++) {
    const State &s = c.record->states[k];
    const MatrixXd ours = get(*c.record, s, "centroidal_bias", 6);
    pin::dccrba(c.model, *c.data, c.q[k], c.v[k]);
    worst = fmax(worst, relative(our_columns(c.map, c.data->Ag),
                                 get(*c.record, s, "centroidal_map", 6, c.record->n)));
    worst = fmax(worst, relative(c.data->dAg * c.v[k], ours));
    pin::computeCentroidalMapTimeVariation(c.model, *c.data, c.q[k], c.v[k]);
    worst = fmax(worst, relative(c.data->dAg * c.v[k], ours));
  }
  return worst;
}

// computeCentroidalMomentumTimeVariation at a = 0: dhg = dAg v, by a
// Newton–Euler pass rather than the matrix.
static double check_centroidal_rate(Robot &c) {
  double worst = 0;
  for (size_t k = 0; k < c.q.size(); k++) {
    const State &s = c.record->states[k];
    pin::computeCentroidalMomentumTimeVariation(c.model, *c.data, c.q[k], c.v[k], c.zero);
    worst = fmax(worst, relative(c.data->dhg.toVector(), get(*c.record, s, "centroidal_bias", 6)));
  }
  return worst;
}

// computeRNEADerivatives at the record's (q, v, a): ∂τ/∂q and ∂τ/∂v
// (∂τ/∂a, the upper half of M, it computes too) by joint name.
static double check_rnea_derivatives(Robot &c) {
  double worst = 0;
  const int n = c.record->n;
  for (size_t k = 0; k < c.q.size(); k++) {
    const State &s = c.record->states[k];
    c.dq.setZero();
    c.dv.setZero();
    c.dtau.setZero();
    pin::computeRNEADerivatives(c.model, *c.data, c.q[k], c.v[k], c.a[k], c.dq, c.dv, c.dtau);
    worst = fmax(worst, relative(ours(c.map, MatrixXd(c.dq)), get(*c.record, s, "dtau_dq", n, n)));
    worst = fmax(worst, relative(ours(c.map, MatrixXd(c.dv)), get(*c.record, s, "dtau_dv", n, n)));
  }
  return worst;
}

// The timed calls: the first frame, every state.
static void time_placement(void *p) {
  Robot &c = *(Robot *)p;
  for (const VectorXd &q : c.q) {
    pin::forwardKinematics(c.model, *c.data, q);
    PEER_KEEP(pin::updateFramePlacement(c.model, *c.data, c.frames[0]).translation().data());
  }
}

static void time_jacobian(void *p) {
  Robot &c = *(Robot *)p;
  for (const VectorXd &q : c.q) {
    pin::computeFrameJacobian(c.model, *c.data, q, c.frames[0], LWA, c.j);
    PEER_KEEP(c.j.data());
  }
}

static void time_bias(void *p) {
  Robot &c = *(Robot *)p;
  for (size_t k = 0; k < c.q.size(); k++) {
    pin::forwardKinematics(c.model, *c.data, c.q[k], c.v[k], c.zero);
    const pin::Motion a = pin::getFrameClassicalAcceleration(c.model, *c.data, c.frames[0], LWA);
    PEER_KEEP(a.linear().data());
    PEER_KEEP(a.angular().data());
  }
}

static void time_com(void *p) {
  Robot &c = *(Robot *)p;
  for (const VectorXd &q : c.q) {
    pin::jacobianCenterOfMass(c.model, *c.data, q, false);
    PEER_KEEP(c.data->com[0].data());
    PEER_KEEP(c.data->Jcom.data());
  }
}

static void time_aba_derivatives(void *p) {
  Robot &c = *(Robot *)p;
  for (size_t k = 0; k < c.q.size(); k++) {
    pin::computeABADerivatives(c.model, *c.data, c.q[k], c.v[k], c.tau[k], c.dq, c.dv, c.dtau);
    PEER_KEEP(c.dq.data());
    PEER_KEEP(c.dv.data());
    PEER_KEEP(c.dtau.data());
  }
}

static void time_com_velocity(void *p) {
  Robot &c = *(Robot *)p;
  for (size_t k = 0; k < c.q.size(); k++) {
    pin::centerOfMass(c.model, *c.data, c.q[k], c.v[k], false);
    PEER_KEEP(c.data->vcom[0].data());
  }
}

static void time_centroidal_map(void *p) {
  Robot &c = *(Robot *)p;
  for (const VectorXd &q : c.q) PEER_KEEP(pin::computeCentroidalMap(c.model, *c.data, q).data());
}

static void time_centroidal_bias(void *p) {
  Robot &c = *(Robot *)p;
  for (size_t k = 0; k < c.q.size(); k++) {
    pin::dccrba(c.model, *c.data, c.q[k], c.v[k]);
    const Eigen::Matrix<double, 6, 1> bias = c.data->dAg * c.v[k];
    PEER_KEEP(bias.data());
  }
}

static void time_centroidal_rate(void *p) {
  Robot &c = *(Robot *)p;
  for (size_t k = 0; k < c.q.size(); k++) {
    const pin::Force &rate =
        pin::computeCentroidalMomentumTimeVariation(c.model, *c.data, c.q[k], c.v[k], c.zero);
    PEER_KEEP(rate.linear().data());
    PEER_KEEP(rate.angular().data());
  }
}

static void time_rnea_derivatives(void *p) {
  Robot &c = *(Robot *)p;
  for (size_t k = 0; k < c.q.size(); k++) {
    pin::computeRNEADerivatives(c.model, *c.data, c.q[k], c.v[k], c.a[k], c.dq, c.dv, c.dtau);
    PEER_KEEP(c.dq.data());
    PEER_KEEP(c.dv.data());
    PEER_KEEP(c.dtau.data());
  }
}

// A row: its name (the JSON's `what`), the method of ours it is checked
// and timed against (`ours`, as kinematics.rs names it: the same as `what`
// but for a second counterpart of one of ours), Pinocchio's counterpart,
// its check and its timed call (none: the answers only).
struct Quantity {
  const char *what, *ours, *pinocchio;
  double (*check)(Robot &);
  void (*time)(void *);
};

static const Quantity QUANTITIES[] = {
    {"frame_placement", "frame_placement", "forwardKinematics + updateFramePlacement",
     check_placement, time_placement},
    {"frame_jacobian", "frame_jacobian", "computeFrameJacobian", check_jacobian, time_jacobian},
    {"frame_velocity", "frame_velocity", "getFrameVelocity", check_velocity, nullptr},
    {"frame_acceleration_bias", "frame_acceleration_bias",
     "forwardKinematics(q, v, 0) + getFrameClassicalAcceleration", check_bias, time_bias},
    {"center_of_mass_and_jacobian", "center_of_mass_and_jacobian", "jacobianCenterOfMass",
     check_com, time_com},
    {"center_of_mass_velocity", "center_of_mass_velocity", "centerOfMass(q, v)",
     check_com_velocity, time_com_velocity},
    {"centroidal_map", "centroidal_map", "computeCentroidalMap", check_centroidal_map,
     time_centroidal_map},
    {"centroidal_map_bias", "centroidal_map_bias", "dccrba + dAg v",
     check_centroidal_bias, time_centroidal_bias},
    {"centroidal_momentum_time_variation", "centroidal_map_bias",
     "computeCentroidalMomentumTimeVariation(q, v, 0)", check_centroidal_rate,
     time_centroidal_rate},
    {"inverse_dynamics_jacobian", "inverse_dynamics_jacobian", "computeRNEADerivatives",
     check_rnea_derivatives, time_rnea_derivatives},
    {"acceleration_jacobian", "acceleration_jacobian", "computeABADerivatives",
     check_aba_derivatives, time_aba_derivatives},
};

static void robot(const std::string &dir, const Record &r, const char *round) {
  if (r.states.empty() || (int)r.names.size() != r.n || r.frames.empty()) {
    fprintf(stderr, "%s: %zu states, %zu names for %d joints, %zu frames\n", r.name.c_str(),
            r.states.size(), r.names.size(), r.n, r.frames.size());
    exit(2);
  }
  Robot c;
  c.record = &r;
  c.model = load(dir + "/" + r.urdf, r.locked, false);
  c.frames = add_frames(c.model, r);
  pin::Data data(c.model);
  c.data = &data;
  c.map = match(c.model, r.name, r.names, r.n);
  // ∂/∂q is by q̇ on our side, by v on Pinocchio's: one and the same only
  // where a joint's q is its angle.
  for (size_t i = 0; i < c.map.nq.size(); i++)
    if (c.map.nq[i] != 1) {
      fprintf(stderr, "%s: %s has %d coordinates in Pinocchio's q\n", r.name.c_str(),
              r.names[i].c_str(), c.map.nq[i]);
      exit(2);
    }
  for (const State &s : r.states) {
    c.q.push_back(pinocchio_q(c.model, c.map, get(r, s, "q", r.n)));
    c.v.push_back(pinocchio_v(c.model, c.map, get(r, s, "v", r.n)));
    c.tau.push_back(pinocchio_v(c.model, c.map, get(r, s, "tau", r.n)));
    c.a.push_back(pinocchio_v(c.model, c.map, get(r, s, "a", r.n)));
  }
  const int nv = c.model.nv;
  c.j = MatrixXd::Zero(6, nv);
  c.dq = c.dv = c.dtau = MatrixXd::Zero(nv, nv);
  c.zero = VectorXd::Zero(nv);
  for (const Quantity &quantity : QUANTITIES) {
    const double worst = quantity.check(c);
    const double tolerance = 1e-12;
    const int ok = worst <= tolerance;
    char time[32] = "null";
    if (ok && quantity.time)
      snprintf(time, sizeof time, "%.3f", peer_cpu_time(quantity.time, &c) / c.q.size());
    printf("{\"peer\": \"pinocchio\", \"what\": \"%s\", \"ours\": \"%s\", \"pinocchio\": \"%s\", "
           "\"system\": \"%s\", \"n\": %d, \"frame\": \"%s\", \"ns\": %s, \"states\": %zu, "
           "\"round\": %s, \"difference\": %.3e, \"tolerance\": %.1e, \"ok\": %s}\n",
           quantity.what, quantity.ours, quantity.pinocchio, r.name.c_str(), r.n,
           r.frames[0].name.c_str(), time, c.q.size(), round, worst, tolerance,
           ok ? "true" : "false");
    fflush(stdout);
    if (!ok) {
      peer_failures++;
      fprintf(stderr, "pinocchio %s %s: relative difference %.3e (> %.1e)\n", quantity.what,
              r.name.c_str(), worst, tolerance);
    }
  }
}

int main(int argc, char **argv) {
  if (argc != 4) {
    fprintf(stderr, "usage: %s ROBOTS_DIR REFERENCE_FILE ROUND\n", argv[0]);
    return 2;
  }
  const std::vector<Record> records = read(argv[2]);
  if (records.empty()) {
    fprintf(stderr, "%s has no robots\n", argv[2]);
    return 2;
  }
  for (const Record &r : records) robot(argv[1], r, argv[3]);
  return peer_failures ? 1 : 0;
}
