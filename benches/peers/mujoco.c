/* MuJoCo (C, from the `mujoco` wheel) on the systems of the reference
 * file: the planar N-link chain with `mj_forward` and one `mj_step` of its
 * RK4 integrator, and the four-bar with `mj_forward`. Each answer is
 * checked against the generated code's before it is timed; one JSON line
 * per result.
 *
 * Usage: mujoco REFERENCE_FILE SCRATCH_XML */
#include "common.h"

#include <mujoco/mujoco.h>

static const char *scratch;

/* Compiles an MJCF text (through a file: the XML loader's entry point). */
static mjModel *load(const char *xml) {
  FILE *f = fopen(scratch, "w");
  if (!f) {
    fprintf(stderr, "cannot write %s\n", scratch);
    exit(2);
  }
  fputs(xml, f);
  fclose(f);
  char error[1000] = "";
  mjModel *m = mj_loadXML(scratch, NULL, error, sizeof error);
  if (!m) {
    fprintf(stderr, "MuJoCo rejected the model: %s\n%s\n", error, xml);
    exit(2);
  }
  return m;
}

typedef struct {
  const mjModel *m;
  mjData *d;
  const double *q, *v;
  int step;
} call_ctx;

/* One mj_forward, or one mj_step from the same state each time. */
static void call(void *p) {
  call_ctx *c = p;
  if (c->step) {
    mju_copy(c->d->qpos, c->q, c->m->nq);
    mju_copy(c->d->qvel, c->v, c->m->nv);
    c->d->time = 0;
    mj_step(c->m, c->d);
  } else {
    mj_forward(c->m, c->d);
  }
  PEER_KEEP(c->d->qacc);
}

/* Point masses on massless rods, a hinge about z at the top of each rod.
 * MuJoCo needs a positive inertia: 1e-12 about the mass's centre changes
 * q̈ by about that much. No geoms, so no collision work. */
static void chain(const peer_record *r) {
  const int n = (int)r->head[0];
  const double g = r->head[1], h = r->head[2];
  const double *mass = peer_get(r, "masses", NULL), *len = peer_get(r, "lengths", NULL);
  static char xml[1 << 16];
  int at = snprintf(xml, sizeof xml,
                    "<mujoco><option gravity=\"0 %.17g 0\" timestep=\"%.17g\" "
                    "integrator=\"RK4\"/><worldbody>",
                    -g, h);
  for (int i = 0; i < n; i++)
    at += snprintf(xml + at, sizeof xml - at,
                   "<body pos=\"0 %.17g 0\"><joint type=\"hinge\" axis=\"0 0 1\"/>"
                   "<inertial pos=\"0 %.17g 0\" mass=\"%.17g\" diaginertia=\"1e-12 1e-12 "
                   "1e-12\"/>",
                   i == 0 ? 0.0 : -len[i - 1], -len[i], mass[i]);
  for (int i = 0; i < n; i++) at += snprintf(xml + at, sizeof xml - at, "</body>");
  snprintf(xml + at, sizeof xml - at, "</worldbody></mujoco>");
  mjModel *m = load(xml);
  mjData *d = mj_makeData(m);
  const double *q = peer_get(r, "q", NULL), *v = peer_get(r, "v", NULL);
  call_ctx c = {m, d, q, v, 0};
  mju_copy(d->qpos, q, n);
  mju_copy(d->qvel, v, n);
  mj_forward(m, d);
  peer_check_and_time("mujoco", "mj_forward", "chain", n,
                      peer_max_difference(d->qacc, peer_get(r, "qdd", NULL), n), 1e-9, call, &c);
  c.step = 1;
  call(&c);
  const double dq = peer_max_difference(d->qpos, peer_get(r, "q1", NULL), n);
  const double dv = peer_max_difference(d->qvel, peer_get(r, "v1", NULL), n);
  peer_check_and_time("mujoco", "mj_step_rk4", "chain", n, fmax(dq, dv), 1e-9, call, &c);
  mj_deleteData(d);
  mj_deleteModel(m);
}

/* The four-bar: crank about the origin, coupler on the crank's tip, rocker
 * about (d, 0), the coupler's far end connected to the rocker's tip. The
 * connect constraint is as stiff as MuJoCo allows (solimp 0.9999): its
 * soft-constraint model still leaves about 1e-4 of the constraint force
 * out, and it drops the J̇ q̇ term, so the answer is checked at rest, where
 * that term is zero, to 1e-3; the time is taken at the moving state. */
static void four_bar(const peer_record *r) {
  const double mass = r->head[0], jm = r->head[1], l = r->head[2], dd = r->head[3], g = r->head[4];
  static char xml[1 << 14];
  snprintf(xml, sizeof xml,
           "<mujoco><option gravity=\"0 %.17g 0\"/><worldbody>"
           "<body name=\"crank\"><joint type=\"hinge\" axis=\"0 0 1\"/>"
           "<inertial pos=\"%.17g 0 0\" mass=\"%.17g\" diaginertia=\"%.17g %.17g %.17g\"/>"
           "<body name=\"coupler\" pos=\"%.17g 0 0\"><joint type=\"hinge\" axis=\"0 0 1\"/>"
           "<inertial pos=\"%.17g 0 0\" mass=\"%.17g\" diaginertia=\"%.17g %.17g %.17g\"/>"
           "</body></body>"
           "<body name=\"rocker\" pos=\"%.17g 0 0\"><joint type=\"hinge\" axis=\"0 0 1\"/>"
           "<inertial pos=\"%.17g 0 0\" mass=\"%.17g\" diaginertia=\"%.17g %.17g %.17g\"/>"
           "</body></worldbody><equality><connect body1=\"coupler\" body2=\"rocker\" "
           "anchor=\"%.17g 0 0\" solimp=\"0.9999 0.9999 0.001 0.5 2\"/></equality></mujoco>",
           -g, l / 2, mass, jm, jm, jm, l, dd / 2, mass, jm, jm, jm, dd, l / 2, mass, jm, jm, jm,
           dd);
  mjModel *m = load(xml);
  mjData *d = mj_makeData(m);
  const double *q = peer_get(r, "q_rest", NULL), *v = peer_get(r, "v_rest", NULL);
  mju_copy(d->qpos, q, 3);
  mju_copy(d->qvel, v, 3);
  mj_forward(m, d);
  const double difference = peer_max_difference(d->qacc, peer_get(r, "qdd_rest", NULL), 3);
  mju_copy(d->qpos, peer_get(r, "q", NULL), 3);
  mju_copy(d->qvel, peer_get(r, "v", NULL), 3);
  call_ctx c = {m, d, NULL, NULL, 0};
  peer_check_and_time("mujoco", "mj_forward", "four_bar", 3, difference, 1e-3, call, &c);
  mj_deleteData(d);
  mj_deleteModel(m);
}

int main(int argc, char **argv) {
  if (argc != 3) {
    fprintf(stderr, "usage: %s REFERENCE_FILE SCRATCH_XML\n", argv[0]);
    return 2;
  }
  scratch = argv[2];
  static peer_record records[16];
  const int n = peer_read(argv[1], records, 16);
  for (int i = 0; i < n; i++) {
    if (!strcmp(records[i].kind, "chain"))
      chain(&records[i]);
    else
      four_bar(&records[i]);
  }
  return peer_failures ? 1 : 0;
}
