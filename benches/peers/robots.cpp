// Pinocchio (C++, from the `pin` wheel) on the robots of the reference
// file written by benches/peers/robots (constrained-robots write: the
// Panda with its fingers locked, the UR5, TALOS, the xArm7, the Kinova
// Jaco 2, the Unitree G1 with its arms locked and whole, and the Panda
// with its finger mimic). Each robot's record names its URDF (under
// example-robot-data's `robots` directory), the joints it holds at zero
// and whether it reads `<mimic>`; this builds Pinocchio's model of the same
// file with `pinocchio::urdf::buildModel` (robots.h, which kinematics.cpp
// shares; fixed base: no root joint),
// `buildReducedModel` for the locked joints (held at zero) and `mimic` as
// the record says, then matches the two models' joints by NAME (every one
// of ours must be a one-degree-of-freedom joint of Pinocchio's, and
// Pinocchio's model must have no other), so that an order that differs, a
// joint one side moves and the other does not, or a count that differs
// is an error rather than a silently permuted comparison. A continuous
// joint, one angle on our side, is (cos, sin) in Pinocchio's q.
//
// At every state of the file it checks `aba` against the generated
// `acceleration`, `crba` (symmetrised) against `mass_matrix` and `rnea`
// against `inverse_dynamics`, each mapped by name, relative to the largest
// entry of the generated answer; only if all of a robot's states agree
// does it time the three over the same states (common.h's statistic on the
// thread's CPU clock, per state). A model with mimic joints, which `aba`
// refuses, has its q̈ checked against the solution of
// `crba` q̈ = τ − `rnea`(q, v, 0) and is not timed. One JSON line per
// result, tagged with ROUND (run.sh alternates three rounds with ours).
//
// Both read the files as written (our reader takes only an angle that is
// a multiple of π/2 to double precision as that multiple, which moves no
// answer beyond rounding), so the check needs no adjusted copy.
//
// The file is read here rather than by common.h's `peer_read`, whose fixed
// records hold 64 numbers a line: the G1's M has 841.
//
// Usage: robots ROBOTS_DIR REFERENCE_FILE ROUND
#include "common.h"
#include "robots.h"

#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/rnea.hpp>

#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

using Eigen::MatrixXd;
using Eigen::VectorXd;

// One state in our order (the record's `names`).
struct State {
  VectorXd q, v, tau, qdd, a, tau_id;
  MatrixXd m;
};

// One robot's record.
struct Record {
  std::string name, urdf;
  int n = 0;
  bool mimic = false;
  std::vector<std::string> locked, names;
  std::vector<State> states;
};

static std::vector<std::string> words(std::istringstream &in) {
  std::vector<std::string> out;
  std::string w;
  while (in >> w) out.push_back(w);
  return out;
}

static VectorXd numbers(std::istringstream &in, const Record &r, const std::string &key) {
  std::vector<double> x;
  double d;
  while (in >> d) x.push_back(d);
  const size_t want = key == "M" ? (size_t)r.n * r.n : (size_t)r.n;
  if (x.size() != want) {
    fprintf(stderr, "%s: %s has %zu entries, not %zu\n", r.name.c_str(), key.c_str(), x.size(),
            want);
    exit(2);
  }
  return Eigen::Map<const VectorXd>(x.data(), x.size());
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
      Record r;
      int mimic = 0;
      in >> r.name >> r.n >> mimic;
      r.mimic = mimic;
      out.push_back(r);
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
    else if (key == "state") r.states.emplace_back();
    else if (r.states.empty()) {
      fprintf(stderr, "%s: `%s` before any `state`\n", r.name.c_str(), key.c_str());
      exit(2);
    } else {
      State &s = r.states.back();
      VectorXd x = numbers(in, r, key);
      if (key == "q") s.q = x;
      else if (key == "v") s.v = x;
      else if (key == "tau") s.tau = x;
      else if (key == "qdd") s.qdd = x;
      else if (key == "a") s.a = x;
      else if (key == "tau_id") s.tau_id = x;
      else if (key == "M") s.m = Eigen::Map<const MatrixXd>(x.data(), r.n, r.n).transpose();
      else {
        fprintf(stderr, "%s: unknown line `%s`\n", r.name.c_str(), key.c_str());
        exit(2);
      }
    }
  }
  return out;
}

// A state in Pinocchio's order (q in its coordinates).
struct PinState {
  VectorXd q, v, tau, a;
};

static PinState to_pinocchio(const pin::Model &model, const Map &map, const State &s) {
  return PinState{pinocchio_q(model, map, s.q), pinocchio_v(model, map, s.v),
                  pinocchio_v(model, map, s.tau), pinocchio_v(model, map, s.a)};
}

struct Timed {
  const pin::Model *model;
  pin::Data *data;
  const std::vector<PinState> *states;
};

static void call_aba(void *p) {
  Timed *c = (Timed *)p;
  for (const PinState &s : *c->states) {
    pin::aba(*c->model, *c->data, s.q, s.v, s.tau);
    PEER_KEEP(c->data->ddq.data());
  }
}

static void call_crba(void *p) {
  Timed *c = (Timed *)p;
  for (const PinState &s : *c->states) {
    pin::crba(*c->model, *c->data, s.q);
    PEER_KEEP(c->data->M.data());
  }
}

static void call_rnea(void *p) {
  Timed *c = (Timed *)p;
  for (const PinState &s : *c->states) {
    pin::rnea(*c->model, *c->data, s.q, s.v, s.a);
    PEER_KEEP(c->data->tau.data());
  }
}

static MatrixXd symmetric_crba(const pin::Model &model, pin::Data &data, const VectorXd &q) {
  pin::crba(model, data, q);
  MatrixXd m = data.M;
  m.triangularView<Eigen::StrictlyLower>() = m.transpose();
  return m;
}

// The largest relative differences of q̈, M and τ over the states.
static void check(const pin::Model &model, pin::Data &data, const Map &map, const Record &r,
                  const std::vector<PinState> &states, double worst[3]) {
  worst[0] = worst[1] = worst[2] = 0;
  for (size_t k = 0; k < states.size(); k++) {
    const State &s = r.states[k];
    const PinState &p = states[k];
    VectorXd qdd;
    if (r.mimic) {
      const MatrixXd m = symmetric_crba(model, data, p.q);
      const VectorXd c = pin::rnea(model, data, p.q, p.v, VectorXd::Zero(model.nv));
      qdd = m.ldlt().solve(p.tau - c);
    } else {
      qdd = pin::aba(model, data, p.q, p.v, p.tau);
    }
    worst[0] = fmax(worst[0], relative(ours(map, qdd), s.qdd));
    worst[1] = fmax(worst[1], relative(ours(map, symmetric_crba(model, data, p.q)), s.m));
    pin::rnea(model, data, p.q, p.v, p.a);
    worst[2] = fmax(worst[2], relative(ours(map, data.tau), s.tau_id));
  }
}

static void robot(const std::string &dir, const Record &r, const char *round) {
  if (r.states.empty() || (int)r.names.size() != r.n) {
    fprintf(stderr, "%s: %zu states, %zu names for %d joints\n", r.name.c_str(),
            r.states.size(), r.names.size(), r.n);
    exit(2);
  }
  const pin::Model model = load(dir + "/" + r.urdf, r.locked, r.mimic);
  pin::Data data(model);
  const Map map = match(model, r.name, r.names, r.n);
  std::vector<PinState> states;
  for (const State &s : r.states) states.push_back(to_pinocchio(model, map, s));
  double worst[3];
  check(model, data, map, r, states, worst);
  Timed ctx{&model, &data, &states};
  // A mimic model's q̈ is crba's solve: compared, not timed.
  const char *what[3] = {r.mimic ? "crba_solve" : "aba", "crba", "rnea"};
  void (*calls[3])(void *) = {call_aba, call_crba, call_rnea};
  for (int k = 0; k < 3; k++) {
    const double tolerance = 1e-12;
    const int ok = worst[k] <= tolerance;
    char time[32] = "null";
    if (ok && !r.mimic)
      snprintf(time, sizeof time, "%.3f", peer_cpu_time(calls[k], &ctx) / states.size());
    printf("{\"peer\": \"pinocchio\", \"what\": \"%s\", \"system\": \"%s\", \"n\": %d, \"ns\": %s, "
           "\"states\": %zu, \"round\": %s, \"difference\": %.3e, "
           "\"tolerance\": %.1e, \"ok\": %s}\n",
           what[k], r.name.c_str(), r.n, time, states.size(), round, worst[k], tolerance,
           ok ? "true" : "false");
    fflush(stdout);
    if (!ok) {
      peer_failures++;
      fprintf(stderr, "pinocchio %s %s: relative difference %.3e (> %.1e)\n", what[k],
              r.name.c_str(), worst[k], tolerance);
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
