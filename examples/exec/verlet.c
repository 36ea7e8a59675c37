/* Störmer–Verlet (kick–drift–kick) as a geomint `exec:` process speaking binary doubles
 * (format=binary): the protocol of docs/PYTHON.md, "Integrators in any language: exec:", in C99.
 * Run: geomint run --problem kepler --method "exec:cmd=build/examples/exec/verlet_c,format=binary" */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { RESET = 1, STEP = 2, GRADIENT = 3, RESULT = 4, TANGENT_STEP = 6, HESSIAN = 7 };

static double *q, *p, *inverse_mass, *g, *answer, *hessian, *block_q, *block_p;
static long n;

/* Every frame is [code, count, count values] in native doubles. */
static void send_frame(int code, const double *values, long count) {
  const double header[2] = {code, (double)count};
  fwrite(header, sizeof(double), 2, stdout);
  if (count > 0) fwrite(values, sizeof(double), (size_t)count, stdout);
  fflush(stdout);
}

/* Reads one frame into a buffer it owns; exits when geomint closes the pipe. */
static double *receive_frame(int *code, long *count) {
  static double *buffer;
  static long capacity;
  double header[2];
  if (fread(header, sizeof(double), 2, stdin) != 2) exit(0);
  *code = (int)header[0];
  *count = (long)header[1];
  if (*count > capacity) {
    capacity = *count;
    buffer = realloc(buffer, (size_t)capacity * sizeof(double));
  }
  if (*count > 0 && fread(buffer, sizeof(double), (size_t)*count, stdin) != (size_t)*count) exit(0);
  return buffer;
}

/* ∇V(x) into out, asked of geomint's problem. */
static void gradient(const double *x, double *out) {
  int code;
  long count;
  send_frame(GRADIENT, x, n);
  const double *values = receive_frame(&code, &count);
  if (code != GRADIENT || count != n) exit(3);
  memcpy(out, values, (size_t)n * sizeof(double));
}

/* ∇²V(x) into hessian (n×n, row-major), asked of geomint's problem: only tangent steps ask. */
static void ask_hessian(const double *x) {
  int code;
  long count;
  send_frame(HESSIAN, x, n);
  const double *values = receive_frame(&code, &count);
  if (code != HESSIAN || count != n * n) exit(3);
  memcpy(hessian, values, (size_t)(n * n) * sizeof(double));
}

/* δp ← δp − c ∇²V δq for the 2n tangent vectors, the columns of the n×2n blocks (row-major). */
static void kick_tangent(double c) {
  for (long i = 0; i < n; ++i) {
    for (long j = 0; j < 2 * n; ++j) {
      double sum = 0;
      for (long k = 0; k < n; ++k) sum += hessian[i * n + k] * block_q[k * 2 * n + j];
      block_p[i * 2 * n + j] -= c * sum;
    }
  }
}

int main(void) {
  /* The handshake is one JSON line in either format. */
  printf("{\"name\": \"verlet_c\", \"order\": 2, \"flags\": [\"explicit\", \"symplectic\", "
         "\"symmetric\"], \"tangent\": true}\n");
  fflush(stdout);
  int have_gradient = 0; /* g = ∇V(q) of the last step: one gradient a step */
  for (;;) {
    int code;
    long count;
    const double *values = receive_frame(&code, &count);
    if (code == RESET) {
      n = (count - 1) / 3; /* t, q, p, M⁻¹ */
      q = realloc(q, (size_t)n * sizeof(double));
      p = realloc(p, (size_t)n * sizeof(double));
      inverse_mass = realloc(inverse_mass, (size_t)n * sizeof(double));
      g = realloc(g, (size_t)n * sizeof(double));
      answer = realloc(answer, (2 * (size_t)n + 4 * (size_t)(n * n)) * sizeof(double));
      hessian = realloc(hessian, (size_t)(n * n) * sizeof(double));
      block_q = realloc(block_q, 2 * (size_t)(n * n) * sizeof(double));
      block_p = realloc(block_p, 2 * (size_t)(n * n) * sizeof(double));
      memcpy(q, values + 1, (size_t)n * sizeof(double));
      memcpy(p, values + 1 + n, (size_t)n * sizeof(double));
      memcpy(inverse_mass, values + 1 + 2 * n, (size_t)n * sizeof(double));
      have_gradient = 0;
      send_frame(RESULT, NULL, 0);
    } else if (code == STEP || code == TANGENT_STEP) {
      const double h = values[0];
      const int tangent = code == TANGENT_STEP;
      if (!have_gradient) gradient(q, g);
      if (tangent) { /* DΦ = kick(∇²V(q⁺)) · drift · kick(∇²V(q)), from (δq, δp) = I */
        for (long i = 0; i < n; ++i) {
          for (long j = 0; j < 2 * n; ++j) {
            block_q[i * 2 * n + j] = j == i ? 1.0 : 0.0;
            block_p[i * 2 * n + j] = j == n + i ? 1.0 : 0.0;
          }
        }
        ask_hessian(q);
        kick_tangent(h / 2);
        for (long i = 0; i < n; ++i) {
          for (long j = 0; j < 2 * n; ++j) {
            block_q[i * 2 * n + j] += h * (inverse_mass[i] * block_p[i * 2 * n + j]);
          }
        }
      }
      /* The arithmetic of geomint's stormer_verlet, so the rows agree bit for bit. */
      for (long i = 0; i < n; ++i) p[i] -= (h / 2) * g[i];
      for (long i = 0; i < n; ++i) q[i] += h * (inverse_mass[i] * p[i]);
      gradient(q, g);
      have_gradient = 1;
      for (long i = 0; i < n; ++i) p[i] -= (h / 2) * g[i];
      memcpy(answer, q, (size_t)n * sizeof(double));
      memcpy(answer + n, p, (size_t)n * sizeof(double));
      if (tangent) { /* q, p, then DΦ row-major: the rows of δq, then those of δp */
        ask_hessian(q);
        kick_tangent(h / 2);
        memcpy(answer + 2 * n, block_q, 2 * (size_t)(n * n) * sizeof(double));
        memcpy(answer + 2 * n + 2 * n * n, block_p, 2 * (size_t)(n * n) * sizeof(double));
      }
      send_frame(RESULT, answer, tangent ? 2 * n + 4 * n * n : 2 * n);
    } else {
      return 2;
    }
  }
}
