// Pinocchio (C++, from the `pin` wheel) on the robots of the reference
// file written by benches/peers/robots (the Panda with its fingers locked,
// the UR5), both read from example-robot-data's URDFs with
// `pinocchio::urdf::buildModel` (fixed base). At every state of the file it
// checks `aba` against the generated `acceleration`, `crba` (symmetrised)
// against `mass_matrix` and `rnea` against `inverse_dynamics`, relative to
// the largest entry of the generated answer; only if all of a robot's
// states agree does it time the three over the same states (common.h's
// statistic on the thread's CPU clock, per state). One JSON line per
// result, tagged with ROUND (run.sh alternates three rounds with ours).
//
// Both read the files as written (our reader takes only an angle that is
// a multiple of π/2 to double precision as that multiple, which moves no
// answer beyond rounding), so the check needs no adjusted copy.
//
// Usage: robots PANDA_URDF UR5_URDF REFERENCE_FILE ROUND
#include "common.h"

#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/joint-configuration.hpp>
#include <pinocchio/algorithm/model.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/multibody.hpp>
#include <pinocchio/parsers/urdf.hpp>

#include <cctype>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace pin = pinocchio;
using Eigen::MatrixXd;
using Eigen::VectorXd;

struct State {
  VectorXd q, v, tau, qdd, a, tau_id;
  MatrixXd m;
};

static VectorXd vec(const peer_record &r, const char *name, int n) {
  int len = 0;
  const double *v = peer_get(&r, name, &len);
  if (len != n) {
    fprintf(stderr, "%s: %s has %d entries, not %d\n", r.kind, name, len, n);
    exit(2);
  }
  return Eigen::Map<const VectorXd>(v, n);
}

// The model of a URDF as written, with the joints named in `locked` held
// at zero.
static pin::Model load(const char *path, const std::vector<std::string> &locked) {
  pin::Model full;
  pin::urdf::buildModel(path, full);
  std::vector<pin::JointIndex> ids;
  for (const std::string &name : locked) {
    if (!full.existJointName(name)) {
      fprintf(stderr, "%s has no joint %s\n", path, name.c_str());
      exit(2);
    }
    ids.push_back(full.getJointId(name));
  }
  if (ids.empty()) return full;
  return pin::buildReducedModel(full, ids, VectorXd::Zero(full.nq));
}

struct Timed {
  const pin::Model *model;
  pin::Data *data;
  const std::vector<State> *states;
};

static void call_aba(void *p) {
  Timed *c = (Timed *)p;
  for (const State &s : *c->states) {
    pin::aba(*c->model, *c->data, s.q, s.v, s.tau);
    PEER_KEEP(c->data->ddq.data());
  }
}

static void call_crba(void *p) {
  Timed *c = (Timed *)p;
  for (const State &s : *c->states) {
    pin::crba(*c->model, *c->data, s.q);
    PEER_KEEP(c->data->M.data());
  }
}

static void call_rnea(void *p) {
  Timed *c = (Timed *)p;
  for (const State &s : *c->states) {
    pin::rnea(*c->model, *c->data, s.q, s.v, s.a);
    PEER_KEEP(c->data->tau.data());
  }
}

static double relative(const MatrixXd &pinocchio, const MatrixXd &generated) {
  return (pinocchio - generated).lpNorm<Eigen::Infinity>() / generated.lpNorm<Eigen::Infinity>();
}

// The largest relative differences of aba, crba and rnea over the states.
static void check(const pin::Model &model, pin::Data &data, const std::vector<State> &states,
                  double worst[3]) {
  worst[0] = worst[1] = worst[2] = 0;
  for (const State &s : states) {
    pin::aba(model, data, s.q, s.v, s.tau);
    worst[0] = fmax(worst[0], relative(data.ddq, s.qdd));
    pin::crba(model, data, s.q);
    MatrixXd m = data.M;
    m.triangularView<Eigen::StrictlyLower>() = m.transpose();
    worst[1] = fmax(worst[1], relative(m, s.m));
    pin::rnea(model, data, s.q, s.v, s.a);
    worst[2] = fmax(worst[2], relative(data.tau, s.tau_id));
  }
}

static void robot(const char *name, const char *path, const std::vector<std::string> &locked,
                  const peer_record *records, int count, const char *round) {
  const pin::Model model = load(path, locked);
  pin::Data data(model);
  const int n = model.nv;
  std::vector<State> states;
  for (int i = 0; i < count; i++) {
    if (strcmp(records[i].kind, name)) continue;
    if ((int)records[i].head[0] != n) {
      fprintf(stderr, "%s: the reference has %d joints, Pinocchio's model %d\n", name,
              (int)records[i].head[0], n);
      exit(2);
    }
    State s{vec(records[i], "q", n),   vec(records[i], "v", n),      vec(records[i], "tau", n),
            vec(records[i], "qdd", n), vec(records[i], "a", n),      vec(records[i], "tau_id", n),
            Eigen::Map<const MatrixXd>(peer_get(&records[i], "M", nullptr), n, n).transpose()};
    states.push_back(s);
  }
  if (states.empty()) {
    fprintf(stderr, "the reference has no %s states\n", name);
    exit(2);
  }
  double worst[3];
  check(model, data, states, worst);
  Timed ctx{&model, &data, &states};
  const char *what[3] = {"aba", "crba", "rnea"};
  void (*calls[3])(void *) = {call_aba, call_crba, call_rnea};
  for (int k = 0; k < 3; k++) {
    const double tolerance = 1e-12;
    const int ok = worst[k] <= tolerance;
    char time[32] = "null";
    if (ok) snprintf(time, sizeof time, "%.3f", peer_cpu_time(calls[k], &ctx) / states.size());
    printf("{\"peer\": \"pinocchio\", \"what\": \"%s\", \"system\": \"%s\", \"n\": %d, \"ns\": %s, "
           "\"states\": %zu, \"round\": %s, \"difference\": %.3e, "
           "\"tolerance\": %.1e, \"ok\": %s}\n",
           what[k], name, n, time, states.size(), round, worst[k], tolerance,
           ok ? "true" : "false");
    fflush(stdout);
    if (!ok) {
      peer_failures++;
      fprintf(stderr, "pinocchio %s %s: relative difference %.3e (> %.1e)\n", what[k], name,
              worst[k], tolerance);
    }
  }
}

int main(int argc, char **argv) {
  if (argc != 5) {
    fprintf(stderr, "usage: %s PANDA_URDF UR5_URDF REFERENCE_FILE ROUND\n", argv[0]);
    return 2;
  }
  static peer_record records[64];
  const int n = peer_read(argv[3], records, 64);
  robot("panda", argv[1], {"panda_finger_joint1", "panda_finger_joint2"}, records, n, argv[4]);
  robot("ur5", argv[2], {}, records, n, argv[4]);
  return peer_failures ? 1 : 0;
}
