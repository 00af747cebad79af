/* Pinocchio generated through CasADi (benches/peers/casadi/generate.py) on
 * the Robots rows' robots and states: at every state of casadi_states.txt
 * (the robots' reference file mapped into CasADi's order by joint name) it
 * checks `aba` against the generated `acceleration`, `crba` (its upper
 * triangle mirrored, as Pinocchio fills only that) against `mass_matrix`
 * and `rnea` against `inverse_dynamics`, relative to the largest entry of
 * ours; only if all of a robot's states agree to 1e-12 does it time the
 * function over the same states (common.h's statistic on the thread's CPU
 * clock, per state). One JSON line per result, `"peer": "casadi"`, tagged
 * with ROUND (run.sh alternates three rounds with ours and Pinocchio's).
 *
 * Usage: casadi STATES_FILE ROUND */
#include "../common.h"

#include "casadi_robots.h"

typedef int (*casadi_call)(const casadi_real **, casadi_real **, casadi_int *, casadi_real *, int);
typedef int (*casadi_size)(casadi_int *, casadi_int *, casadi_int *, casadi_int *);

typedef struct {
  const char *name;
  int n, nq;
  casadi_call aba;
  casadi_size aba_work;
  casadi_call crba;
  casadi_size crba_work;
  casadi_call rnea;
  casadi_size rnea_work;
} casadi_robot;

#include "casadi_registry.h"

#define MAX_STATES 64
#define MAX_N 64

/* One state: CasADi's inputs and our answers in its order. */
typedef struct {
  double q[MAX_N], v[MAX_N], tau[MAX_N], a[MAX_N], qdd[MAX_N], tau_id[MAX_N];
  double m[MAX_N * MAX_N];
} state;

typedef struct {
  char name[32];
  int n, nq, count;
  state states[MAX_STATES];
} record;

/* A function of CasADi's with its work arrays, and the inputs of one call. */
typedef struct {
  casadi_call f;
  const casadi_real *arg[8];
  casadi_real *res[8];
  casadi_int iw[256];
  casadi_real *w;
} call;

static void prepare(call *c, casadi_call f, casadi_size size) {
  casadi_int sz_arg, sz_res, sz_iw, sz_w;
  size(&sz_arg, &sz_res, &sz_iw, &sz_w);
  if (sz_arg > 8 || sz_res > 8 || sz_iw > 256) {
    fprintf(stderr, "casadi: work sizes %lld %lld %lld beyond the harness's\n", (long long)sz_arg,
            (long long)sz_res, (long long)sz_iw);
    exit(2);
  }
  c->f = f;
  c->w = malloc(sizeof(casadi_real) * (sz_w > 0 ? sz_w : 1));
}

static void line(FILE *f, const char *key, double *out, int len, const char *robot) {
  char word[16];
  if (fscanf(f, "%15s", word) != 1 || strcmp(word, key) != 0) {
    fprintf(stderr, "%s: expected `%s`\n", robot, key);
    exit(2);
  }
  for (int i = 0; i < len; i++)
    if (fscanf(f, "%lf", &out[i]) != 1) {
      fprintf(stderr, "%s: `%s` has fewer than %d numbers\n", robot, key, len);
      exit(2);
    }
}

/* The next robot of `f` into `r`; 0 at the end of the file. */
static int read_record(FILE *f, record *r) {
  char word[16];
  if (fscanf(f, "%15s", word) != 1) return 0;
  if (strcmp(word, "robot") != 0 || fscanf(f, "%31s %d %d %d", r->name, &r->n, &r->nq, &r->count) != 4 ||
      r->n > MAX_N || r->nq > MAX_N || r->count > MAX_STATES || r->count < 1) {
    fprintf(stderr, "casadi: bad robot header\n");
    exit(2);
  }
  for (int k = 0; k < r->count; k++) {
    state *s = &r->states[k];
    if (fscanf(f, "%15s", word) != 1 || strcmp(word, "state") != 0) {
      fprintf(stderr, "%s: expected `state`\n", r->name);
      exit(2);
    }
    line(f, "q", s->q, r->nq, r->name);
    line(f, "v", s->v, r->n, r->name);
    line(f, "tau", s->tau, r->n, r->name);
    line(f, "a", s->a, r->n, r->name);
    line(f, "qdd", s->qdd, r->n, r->name);
    line(f, "tau_id", s->tau_id, r->n, r->name);
    line(f, "M", s->m, r->n * r->n, r->name);
  }
  return 1;
}

/* What one timed loop runs: one of the three functions over the states. */
typedef struct {
  call *c;
  record *r;
  int what; /* 0 aba, 1 crba, 2 rnea */
  double out[MAX_N * MAX_N];
} timed;

static void run(timed *t, const state *s) {
  call *c = t->c;
  c->res[0] = t->out;
  if (t->what == 1) {
    c->arg[0] = s->q;
  } else {
    c->arg[0] = s->q;
    c->arg[1] = s->v;
    c->arg[2] = t->what == 0 ? s->tau : s->a;
  }
  c->f(c->arg, c->res, c->iw, c->w, 0);
}

static void loop(void *p) {
  timed *t = p;
  for (int k = 0; k < t->r->count; k++) {
    run(t, &t->r->states[k]);
    PEER_KEEP(t->out);
  }
}

/* The worst difference over the states relative to the largest entry of ours. */
static double check(timed *t) {
  const record *r = t->r;
  const int n = r->n;
  double worst = 0;
  for (int k = 0; k < r->count; k++) {
    const state *s = &r->states[k];
    run(t, s);
    const double *want = t->what == 0 ? s->qdd : t->what == 1 ? s->m : s->tau_id;
    const int len = t->what == 1 ? n * n : n;
    if (t->what == 1)
      for (int i = 0; i < n; i++)
        for (int j = 0; j < i; j++) t->out[i + j * n] = t->out[j + i * n];
    double scale = 0;
    for (int i = 0; i < len; i++) scale = fmax(scale, fabs(want[i]));
    /* CasADi's dense outputs are column-major; M is symmetric either way. */
    worst = fmax(worst, peer_max_difference(t->out, want, len) / scale);
  }
  return worst;
}

static void robot(record *r, const char *round) {
  const casadi_robot *f = NULL;
  for (size_t i = 0; i < sizeof casadi_robots / sizeof casadi_robots[0]; i++)
    if (strcmp(casadi_robots[i].name, r->name) == 0) f = &casadi_robots[i];
  if (!f || f->n != r->n || f->nq != r->nq) {
    fprintf(stderr, "casadi: no functions for %s (n %d, nq %d)\n", r->name, r->n, r->nq);
    exit(2);
  }
  const char *names[3] = {"aba", "crba", "rnea"};
  casadi_call calls[3] = {f->aba, f->crba, f->rnea};
  casadi_size sizes[3] = {f->aba_work, f->crba_work, f->rnea_work};
  static call c;
  static timed t;
  for (int k = 0; k < 3; k++) {
    prepare(&c, calls[k], sizes[k]);
    t.c = &c;
    t.r = r;
    t.what = k;
    const double worst = check(&t);
    const double tolerance = 1e-12;
    const int ok = worst <= tolerance;
    char time[32] = "null";
    if (ok) snprintf(time, sizeof time, "%.3f", peer_cpu_time(loop, &t) / r->count);
    printf("{\"peer\": \"casadi\", \"what\": \"%s\", \"system\": \"%s\", \"n\": %d, \"ns\": %s, "
           "\"states\": %d, \"round\": %s, \"difference\": %.3e, \"tolerance\": %.1e, \"ok\": %s}\n",
           names[k], r->name, r->n, time, r->count, round, worst, tolerance, ok ? "true" : "false");
    fflush(stdout);
    if (!ok) {
      peer_failures++;
      fprintf(stderr, "casadi %s %s: relative difference %.3e (> %.1e)\n", names[k], r->name, worst,
              tolerance);
    }
    free(c.w);
  }
}

int main(int argc, char **argv) {
  if (argc != 3) {
    fprintf(stderr, "usage: %s STATES_FILE ROUND\n", argv[0]);
    return 2;
  }
  FILE *f = fopen(argv[1], "r");
  if (!f) {
    fprintf(stderr, "cannot open %s\n", argv[1]);
    return 2;
  }
  static record r;
  int robots = 0;
  while (read_record(f, &r)) {
    robot(&r, argv[2]);
    robots++;
  }
  fclose(f);
  if (!robots) {
    fprintf(stderr, "%s has no robots\n", argv[1]);
    return 2;
  }
  return peer_failures ? 1 : 0;
}
