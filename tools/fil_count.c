/* fil_count.c: one closed-loop firmware-in-the-loop run in C, for counting
 * the instructions of plant + firmware per tick:
 *   valgrind --tool=callgrind --toggle-collect=pyins_fil_run ./fil_count DIR
 * DIR is written by `tools/bench_fil.py --dump DIR` from the very objects
 * pyins.fil.run_fil builds (raw native-endian bytes, this machine kind only):
 *   config.bin        pyins_config the firmware was initialised from
 *   plant_state.bin   pyins_plant_state at the start
 *   table_config.bin  pyins_table_config
 *   imu_errors.bin    pyins_imu_errors
 *   params.bin        int64 period, nodes, every, n, phase0; double dt
 *   omega.bin, force.bin   period * nodes * 3 doubles (the ship's node rates)
 *   x.bin, w.bin      nodes doubles (Gauss-Legendre abscissae and weights)
 *   gyro_noise.bin, accel_noise.bin   n * 3 doubles (absent: no noise)
 *   sum_omega.bin, sum_force.bin   period * 3 doubles, the weighted node
 *                     sums of a table at rest (absent: summed per tick)
 * Calls pyins_fil_run once over all n ticks and prints the ticks done and
 * the last kept output's lat_rad (%.17g), which bench_fil.py compares with
 * the Python run's bit for bit, and the call's wall time (loop_s: the
 * closed loop alone, no Python around it; meaningless under valgrind). */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "pyins_core.h"
#include "pyins_plant.h"

static unsigned char mem[1 << 16] __attribute__((aligned(64)));
static const char *dir;

/* The whole file DIR/name (malloc'd) and its size; NULL if absent and optional. */
static void *read_file(const char *name, size_t *size, int optional) {
    char path[4096];
    FILE *f;
    long len;
    void *buf;
    snprintf(path, sizeof path, "%s/%s", dir, name);
    f = fopen(path, "rb");
    if (f == NULL) {
        if (optional) return NULL;
        fprintf(stderr, "fil_count: cannot open %s\n", path);
        exit(2);
    }
    if (fseek(f, 0, SEEK_END) != 0 || (len = ftell(f)) < 0 || fseek(f, 0, SEEK_SET) != 0) {
        fprintf(stderr, "fil_count: cannot size %s\n", path);
        exit(2);
    }
    buf = malloc(len > 0 ? (size_t)len : 1u);
    if (buf == NULL || fread(buf, 1, (size_t)len, f) != (size_t)len) {
        fprintf(stderr, "fil_count: cannot read %s\n", path);
        exit(2);
    }
    fclose(f);
    *size = (size_t)len;
    return buf;
}

/* DIR/name into the struct at dst, refusing a size other than sizeof. */
static void read_struct(const char *name, void *dst, size_t want, const char *type) {
    size_t size = 0;
    void *buf = read_file(name, &size, 0);
    if (size != want) {
        fprintf(stderr,
                "fil_count: %s/%s holds %zu bytes but sizeof(%s) is %zu here: the dump comes "
                "from another build or machine kind; dump again with tools/bench_fil.py --dump\n",
                dir, name, size, type, want);
        exit(3);
    }
    memcpy(dst, buf, want);
    free(buf);
}

/* DIR/name as count doubles (NULL if optional and absent). */
static double *read_doubles(const char *name, size_t count, int optional) {
    size_t size = 0;
    double *buf = read_file(name, &size, optional);
    if (buf != NULL && size != count * sizeof(double)) {
        fprintf(stderr, "fil_count: %s/%s holds %zu bytes, expected %zu doubles (%zu bytes)\n", dir,
                name, size, count, count * sizeof(double));
        exit(3);
    }
    return buf;
}

int main(int argc, char **argv) {
    pyins_config cfg;
    pyins_plant_state st;
    pyins_table_config table;
    pyins_imu_errors err;
    int64_t params[5];
    double dt;
    size_t size = 0, n, capacity, n_done = 0, n_out = 0;
    unsigned char *pbuf;
    double *omega, *force, *x, *w, *g_noise, *a_noise, *sum_omega, *sum_force;
    pyins_output *outputs;
    pyins_plant_record *records;
    int status;
    struct timespec t0, t1;
    if (argc != 2) {
        fprintf(stderr, "usage: fil_count DIR   (DIR from tools/bench_fil.py --dump DIR)\n");
        return 2;
    }
    dir = argv[1];
    read_struct("config.bin", &cfg, sizeof cfg, "pyins_config");
    read_struct("plant_state.bin", &st, sizeof st, "pyins_plant_state");
    read_struct("table_config.bin", &table, sizeof table, "pyins_table_config");
    read_struct("imu_errors.bin", &err, sizeof err, "pyins_imu_errors");
    pbuf = read_file("params.bin", &size, 0);
    if (size != sizeof params + sizeof dt) {
        fprintf(stderr, "fil_count: %s/params.bin holds %zu bytes, expected %zu\n", dir, size,
                sizeof params + sizeof dt);
        return 3;
    }
    memcpy(params, pbuf, sizeof params);
    memcpy(&dt, pbuf + sizeof params, sizeof dt);
    free(pbuf);
    /* params: period, nodes, every, n, phase0 */
    if (params[0] < 1 || params[1] < 1 || params[1] > 64 || params[2] < 1 || params[3] < 0 || params[4] < 0) {
        fprintf(stderr, "fil_count: bad params.bin (period %lld nodes %lld every %lld n %lld phase0 %lld)\n",
                (long long)params[0], (long long)params[1], (long long)params[2], (long long)params[3],
                (long long)params[4]);
        return 3;
    }
    n = (size_t)params[3];
    omega = read_doubles("omega.bin", (size_t)params[0] * (size_t)params[1] * 3u, 0);
    force = read_doubles("force.bin", (size_t)params[0] * (size_t)params[1] * 3u, 0);
    x = read_doubles("x.bin", (size_t)params[1], 0);
    w = read_doubles("w.bin", (size_t)params[1], 0);
    g_noise = read_doubles("gyro_noise.bin", n * 3u, 1);
    a_noise = read_doubles("accel_noise.bin", n * 3u, 1);
    sum_omega = read_doubles("sum_omega.bin", (size_t)params[0] * 3u, 1);
    sum_force = read_doubles("sum_force.bin", (size_t)params[0] * 3u, 1);

    if (pyins_core_size() > sizeof mem || pyins_core_align() > 64u) {
        fprintf(stderr, "fil_count: instance (%zu bytes, alignment %zu) does not fit the static buffer\n",
                pyins_core_size(), pyins_core_align());
        return 2;
    }
    status = pyins_init(mem, sizeof mem, &cfg);
    if (status != PYINS_OK) {
        fprintf(stderr, "fil_count: pyins_init returned %d\n", status);
        return 3;
    }
    capacity = n / (size_t)params[2] + 1u;
    outputs = malloc(capacity * sizeof *outputs);
    records = malloc(capacity * sizeof *records);
    if (outputs == NULL || records == NULL) {
        fprintf(stderr, "fil_count: out of memory\n");
        return 2;
    }
    clock_gettime(CLOCK_MONOTONIC, &t0);
    status = pyins_fil_run((pyins_core *)mem, &st, &table, &err, omega, force, x, w, sum_omega, sum_force,
                           (int32_t)params[1],
                           params[0], params[4], g_noise, a_noise, n, dt, (size_t)params[2], outputs,
                           records, capacity, &n_done, &n_out);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    if (status != PYINS_OK) {
        fprintf(stderr, "fil_count: pyins_fil_run returned %d after %zu ticks\n", status, n_done);
        return 4;
    }
    if (n_out == 0) {
        fprintf(stderr, "fil_count: no output kept (n %zu < every %lld)\n", n, (long long)params[2]);
        return 4;
    }
    printf("ticks %zu lat %.17g outputs %zu alpha %.17g loop_s %.6f\n", n_done, outputs[n_out - 1].lat_rad,
           n_out, st.alpha_rad, (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec));
    free(outputs);
    free(records);
    free(omega);
    free(force);
    free(x);
    free(w);
    free(g_noise);
    free(a_noise);
    free(sum_omega);
    free(sum_force);
    return 0;
}
