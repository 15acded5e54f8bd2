/* Planar pendulum (unit mass, Cartesian), Baumgarte law, explicit midpoint rule (5.4)-(5.7)
 * with a = 1/2, sigma = 1: the C reference of studies/bench_throughput.py.
 *
 * Same mathematics as stabdae's generic kernel for kernels/pendulum.py:
 *   g  = (f, fdot),  f = x^2 + y^2 - l^2,  fdot = 2 (x vx + y vy)
 *   S  = F F^T = 4 (x^2 + y^2),  rl = A g - c + F z = a0 f + a1 fdot - 2|v|^2 + 2 y g
 *   lambda = rl / S,  vdot = F^T lambda - (0, g)
 * Residual max-norms are stored every `save_every` steps as float32, like stabdae.
 *
 * Two forms: run_scalar integrates one member per loop iteration (all its steps), and
 * run_blocked integrates blocks of members in lockstep, structure-of-arrays, with the
 * member loop innermost so that gcc vectorizes it.  Both are OpenMP-parallel over
 * members / blocks.  run_blocked_checked is run_blocked with the failure test stabdae's
 * step makes: each stage's pivot S must pass S > 1e-12 |S| (a singular constraint matrix
 * otherwise), and each member keeps the OR of its tests (its status is read once, at the
 * end, where stabdae reads it at every stored sample); the same numbers otherwise.
 */
#include <math.h>
#include <omp.h>
#include <stdint.h>

#define BLOCK 64

/* the OpenMP threads of the runs that follow (the benchmark's one-thread rows) */
void set_threads(int n) { omp_set_num_threads(n); }

static inline void rhs(double x, double y, double vx, double vy, double g, double l,
                       double a0, double a1, double *ax, double *ay) {
    double f = x * x + y * y - l * l;
    double fd = 2.0 * x * vx + 2.0 * y * vy;
    double rl = a0 * f + a1 * fd - 2.0 * (vx * vx + vy * vy) + 2.0 * y * g;
    double lam = rl / (4.0 * x * x + 4.0 * y * y);
    *ax = 2.0 * x * lam;
    *ay = 2.0 * y * lam - g;
}

static inline float norm_of(double x, double y, double vx, double vy, double l) {
    double f = fabs(x * x + y * y - l * l);
    double fd = fabs(2.0 * x * vx + 2.0 * y * vy);
    return (float)(f > fd ? f : fd);
}

void run_scalar(int64_t members, const double *x0, double g, double l, double a0, double a1,
                double tau, int64_t nsteps, int64_t save_every, float *norms, double *xf) {
    int64_t nsave = nsteps / save_every + 1;
#pragma omp parallel for schedule(static)
    for (int64_t j = 0; j < members; j++) {
        double x = x0[4 * j], y = x0[4 * j + 1], vx = x0[4 * j + 2], vy = x0[4 * j + 3];
        norms[j * nsave] = norm_of(x, y, vx, vy, l);
        for (int64_t i = 1; i <= nsteps; i++) {
            double ax, ay, bx, by;
            rhs(x, y, vx, vy, g, l, a0, a1, &ax, &ay);
            double xm = x + 0.5 * tau * vx, ym = y + 0.5 * tau * vy;
            double vxm = vx + 0.5 * tau * ax, vym = vy + 0.5 * tau * ay;
            rhs(xm, ym, vxm, vym, g, l, a0, a1, &bx, &by);
            x += tau * vxm;
            y += tau * vym;
            vx += tau * bx;
            vy += tau * by;
            if (i % save_every == 0) norms[j * nsave + i / save_every] = norm_of(x, y, vx, vy, l);
        }
        xf[4 * j] = x; xf[4 * j + 1] = y; xf[4 * j + 2] = vx; xf[4 * j + 3] = vy;
    }
}

void run_blocked(int64_t members, const double *x0, double g, double l, double a0, double a1,
                 double tau, int64_t nsteps, int64_t save_every, float *norms, double *xf) {
    int64_t nsave = nsteps / save_every + 1;
    int64_t nblocks = (members + BLOCK - 1) / BLOCK;
#pragma omp parallel for schedule(static)
    for (int64_t b = 0; b < nblocks; b++) {
        double X[BLOCK], Y[BLOCK], VX[BLOCK], VY[BLOCK];
        int64_t lo = b * BLOCK, cnt = members - lo < BLOCK ? members - lo : BLOCK;
        for (int64_t j = 0; j < BLOCK; j++) {  /* pad a short last block with member lo */
            int64_t m = lo + (j < cnt ? j : 0);
            X[j] = x0[4 * m]; Y[j] = x0[4 * m + 1]; VX[j] = x0[4 * m + 2]; VY[j] = x0[4 * m + 3];
        }
        for (int64_t j = 0; j < cnt; j++) norms[(lo + j) * nsave] = norm_of(X[j], Y[j], VX[j], VY[j], l);
        for (int64_t i = 1; i <= nsteps; i++) {
#pragma omp simd
            for (int64_t j = 0; j < BLOCK; j++) {
                double ax, ay, bx, by;
                double x = X[j], y = Y[j], vx = VX[j], vy = VY[j];
                rhs(x, y, vx, vy, g, l, a0, a1, &ax, &ay);
                double xm = x + 0.5 * tau * vx, ym = y + 0.5 * tau * vy;
                double vxm = vx + 0.5 * tau * ax, vym = vy + 0.5 * tau * ay;
                rhs(xm, ym, vxm, vym, g, l, a0, a1, &bx, &by);
                X[j] = x + tau * vxm;
                Y[j] = y + tau * vym;
                VX[j] = vx + tau * bx;
                VY[j] = vy + tau * by;
            }
            if (i % save_every == 0)
                for (int64_t j = 0; j < cnt; j++)
                    norms[(lo + j) * nsave + i / save_every] = norm_of(X[j], Y[j], VX[j], VY[j], l);
        }
        for (int64_t j = 0; j < cnt; j++) {
            xf[4 * (lo + j)] = X[j]; xf[4 * (lo + j) + 1] = Y[j];
            xf[4 * (lo + j) + 2] = VX[j]; xf[4 * (lo + j) + 3] = VY[j];
        }
    }
}

/* rhs with the pivot S returned beside the accelerations */
static inline void rhs_s(double x, double y, double vx, double vy, double g, double l,
                         double a0, double a1, double *ax, double *ay, double *s) {
    double f = x * x + y * y - l * l;
    double fd = 2.0 * x * vx + 2.0 * y * vy;
    double rl = a0 * f + a1 * fd - 2.0 * (vx * vx + vy * vy) + 2.0 * y * g;
    *s = 4.0 * x * x + 4.0 * y * y;
    double lam = rl / *s;
    *ax = 2.0 * x * lam;
    *ay = 2.0 * y * lam - g;
}

/* run_blocked with each stage's pivot tested, as stabdae's step tests it; `failed` (one
 * byte per member) gets 1 where a test failed */
void run_blocked_checked(int64_t members, const double *x0, double g, double l, double a0,
                         double a1, double tau, int64_t nsteps, int64_t save_every,
                         float *norms, double *xf, unsigned char *failed) {
    int64_t nsave = nsteps / save_every + 1;
    int64_t nblocks = (members + BLOCK - 1) / BLOCK;
#pragma omp parallel for schedule(static)
    for (int64_t b = 0; b < nblocks; b++) {
        double X[BLOCK], Y[BLOCK], VX[BLOCK], VY[BLOCK];
        int64_t bad[BLOCK];  /* (one byte each: gcc unrolled the member loop, 1.3-1.5x the time) */
        int64_t lo = b * BLOCK, cnt = members - lo < BLOCK ? members - lo : BLOCK;
        for (int64_t j = 0; j < BLOCK; j++) {
            int64_t m = lo + (j < cnt ? j : 0);
            X[j] = x0[4 * m]; Y[j] = x0[4 * m + 1]; VX[j] = x0[4 * m + 2]; VY[j] = x0[4 * m + 3];
            bad[j] = 0;
        }
        for (int64_t j = 0; j < cnt; j++) norms[(lo + j) * nsave] = norm_of(X[j], Y[j], VX[j], VY[j], l);
        for (int64_t i = 1; i <= nsteps; i++) {
#pragma omp simd
            for (int64_t j = 0; j < BLOCK; j++) {
                double ax, ay, bx, by, s1, s2;
                double x = X[j], y = Y[j], vx = VX[j], vy = VY[j];
                rhs_s(x, y, vx, vy, g, l, a0, a1, &ax, &ay, &s1);
                double xm = x + 0.5 * tau * vx, ym = y + 0.5 * tau * vy;
                double vxm = vx + 0.5 * tau * ax, vym = vy + 0.5 * tau * ay;
                rhs_s(xm, ym, vxm, vym, g, l, a0, a1, &bx, &by, &s2);
                bad[j] |= !(s1 > 1e-12 * fabs(s1)) | !(s2 > 1e-12 * fabs(s2));
                X[j] = x + tau * vxm;
                Y[j] = y + tau * vym;
                VX[j] = vx + tau * bx;
                VY[j] = vy + tau * by;
            }
            if (i % save_every == 0)
                for (int64_t j = 0; j < cnt; j++)
                    norms[(lo + j) * nsave + i / save_every] = norm_of(X[j], Y[j], VX[j], VY[j], l);
        }
        for (int64_t j = 0; j < cnt; j++) {
            xf[4 * (lo + j)] = X[j]; xf[4 * (lo + j) + 1] = Y[j];
            xf[4 * (lo + j) + 2] = VX[j]; xf[4 * (lo + j) + 3] = VY[j];
            failed[lo + j] = bad[j];
        }
    }
}
