/* Shared by the peer benchmarks: reading benches' reference file (written
 * by chains/examples/peer_reference.rs) and timing a call.
 *
 * The reference file is a sequence of records; a record starts with a
 * header line (`chain N g h` or `four_bar m jm l d g`; `quadruped 18` or
 * `go1 18`, `g1 35`, `g1flat 35` or `five_bar 4` in the contacts' file, benches/peers/robots/src/bin/contacts.rs)
 * followed by named vector lines (`q 0.1 0.2 …`). The robots' file, whose
 * lines are longer than these records hold, is read by robots.cpp. */
#ifndef PEERS_COMMON_H
#define PEERS_COMMON_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define PEER_MAX 64

typedef struct {
  char name[16];
  int len;
  double v[PEER_MAX];
} peer_vector;

typedef struct {
  char kind[16];    /* "chain", "four_bar", "quadruped", "go1", "g1", "g1flat" or "five_bar" */
  double head[8];   /* the numbers on the header line */
  int nhead;
  peer_vector vec[12];
  int nvec;
} peer_record;

/* Reads every record of `path` into `out` (at most `max`); returns how many. */
static int peer_read(const char *path, peer_record *out, int max) {
  FILE *f = fopen(path, "r");
  if (!f) {
    fprintf(stderr, "cannot open %s\n", path);
    exit(2);
  }
  char line[8192];
  int n = -1;
  while (fgets(line, sizeof line, f)) {
    char *tok = strtok(line, " \n");
    if (!tok) continue;
    if (!strcmp(tok, "chain") || !strcmp(tok, "four_bar") || !strcmp(tok, "quadruped") ||
        !strcmp(tok, "five_bar") || !strcmp(tok, "go1") || !strcmp(tok, "g1") || !strcmp(tok, "g1flat")) {
      if (++n >= max) break;
      memset(&out[n], 0, sizeof out[n]);
      snprintf(out[n].kind, sizeof out[n].kind, "%s", tok);
      while ((tok = strtok(NULL, " \n")) && out[n].nhead < 8)
        out[n].head[out[n].nhead++] = strtod(tok, NULL);
    } else if (n >= 0 && out[n].nvec < 12) {
      peer_vector *v = &out[n].vec[out[n].nvec++];
      snprintf(v->name, sizeof v->name, "%s", tok);
      while ((tok = strtok(NULL, " \n")) && v->len < PEER_MAX) v->v[v->len++] = strtod(tok, NULL);
    }
  }
  fclose(f);
  return n + 1 > max ? max : n + 1;
}

/* The vector named `name` of a record; exits if it is missing. */
static const double *peer_get(const peer_record *r, const char *name, int *len) {
  for (int i = 0; i < r->nvec; i++)
    if (!strcmp(r->vec[i].name, name)) {
      if (len) *len = r->vec[i].len;
      return r->vec[i].v;
    }
  fprintf(stderr, "record %s lacks %s\n", r->kind, name);
  exit(2);
}

static double peer_now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return t.tv_sec * 1e9 + t.tv_nsec;
}

/* Keeps the compiler from discarding a result. */
#define PEER_KEEP(p) __asm__ volatile("" : : "r"(p) : "memory")

static int peer_compare(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/* The thread's CPU time in ns: the robots' and the contacts' rows are timed
 * on it on both sides (the Rust programs read the same clock), since on a
 * shared machine the wall time of a pinned loop also counts the time other
 * processes held its core (observed: the same call 10× slower from one round
 * to the next). */
static double peer_cpu_now(void) {
  struct timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return t.tv_sec * 1e9 + t.tv_nsec;
}

/* Median time per call in ns of `call(ctx)` on the clock `now`: batches of
 * about 5 ms after a warm-up, 31 of them (the same statistic as criterion's
 * median, near enough for ratios of 2 and more). */
static double peer_time_on(double (*now)(void), void (*call)(void *), void *ctx) {
  long iters = 1;
  for (;;) {
    double t0 = now();
    for (long i = 0; i < iters; i++) call(ctx);
    if (now() - t0 > 5e6) break;
    iters *= 2;
  }
  double samples[31];
  for (int s = 0; s < 31; s++) {
    double t0 = now();
    for (long i = 0; i < iters; i++) call(ctx);
    samples[s] = (now() - t0) / iters;
  }
  qsort(samples, 31, sizeof samples[0], peer_compare);
  return samples[15];
}

/* `peer_time_on` the wall clock (the chains and the four-bar). */
static double peer_time(void (*call)(void *), void *ctx) {
  return peer_time_on(peer_now, call, ctx);
}

/* `peer_time_on` the thread's CPU clock (the robots and the contacts). */
static double peer_cpu_time(void (*call)(void *), void *ctx) {
  return peer_time_on(peer_cpu_now, call, ctx);
}

/* Largest |a − b| over n entries. */
static double peer_max_difference(const double *a, const double *b, int n) {
  double m = 0;
  for (int i = 0; i < n; i++) m = fmax(m, fabs(a[i] - b[i]));
  return m;
}

/* Failures so far: the programs exit with 1 if any answer disagreed. */
static int peer_failures = 0;

/* Checks an answer, and only if it agrees with the reference times `call`;
 * prints the result as a JSON line (a disagreeing answer gets no time). */
static void peer_check_and_time(const char *peer, const char *what, const char *system, int n,
                                double difference, double tolerance, void (*call)(void *),
                                void *ctx) {
  int ok = difference <= tolerance;
  double ns = ok ? peer_time(call, ctx) : NAN;
  char time[32];
  if (ok)
    snprintf(time, sizeof time, "%.3f", ns);
  else
    snprintf(time, sizeof time, "null");
  printf("{\"peer\": \"%s\", \"what\": \"%s\", \"system\": \"%s\", \"n\": %d, \"ns\": %s, "
         "\"difference\": %.3e, \"tolerance\": %.1e, \"ok\": %s}\n",
         peer, what, system, n, time, difference, tolerance, ok ? "true" : "false");
  fflush(stdout);
  if (!ok) {
    peer_failures++;
    fprintf(stderr, "%s %s %s N=%d: answer differs by %.3e (> %.1e)\n", peer, what, system, n,
            difference, tolerance);
  }
}

#endif
