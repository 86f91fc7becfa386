/* replay_main.c: run fuzz inputs through the fuzz target without libFuzzer
 * (ctest's fuzz_replay tests, under the sanitizers or valgrind).
 *
 *   fuzz_replay [--seeds] [FILE | DIR]...   replay the built-in seeds and every
 *                                           file (directories: every file in them)
 *   fuzz_replay --write-seeds DIR           write the built-in seeds as files
 *
 * An invariant violation aborts (non-zero exit); otherwise it prints how many
 * inputs ran and returns 0. */
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "fuzz_c_api.h"

#define FUZZ_MAX_INPUT (1u << 20)

static unsigned char g_buf[FUZZ_MAX_INPUT];
static unsigned long g_count = 0;

static int run_file(const char *path) {
    FILE *fp = fopen(path, "rb");
    size_t n;
    if (fp == NULL) {
        fprintf(stderr, "cannot open %s\n", path);
        return 1;
    }
    n = fread(g_buf, 1, sizeof g_buf, fp);
    fclose(fp);
    LLVMFuzzerTestOneInput(g_buf, n);
    ++g_count;
    return 0;
}

static int is_dir(const char *path) {
    struct stat st;
    return stat(path, &st) == 0 && S_ISDIR(st.st_mode);
}

static int run_path(const char *path) {
    DIR *d;
    struct dirent *e;
    int rc = 0;
    if (!is_dir(path)) return run_file(path);
    d = opendir(path);
    if (d == NULL) {
        fprintf(stderr, "cannot open directory %s\n", path);
        return 1;
    }
    while ((e = readdir(d)) != NULL) {
        char full[4096];
        if (e->d_name[0] == '.') continue;   /* ., .., hidden files */
        if (strcmp(e->d_name, "README") == 0 || strstr(e->d_name, ".md") != NULL) continue;
        snprintf(full, sizeof full, "%s/%s", path, e->d_name);
        if (!is_dir(full)) rc |= run_file(full);
    }
    closedir(d);
    return rc;
}

int main(int argc, char **argv) {
    int i, rc = 0;
    if (argc == 3 && strcmp(argv[1], "--write-seeds") == 0) {
        for (i = 0; i < fuzz_seed_count(); ++i) {
            char path[4096];
            const size_t n = fuzz_seed(i, g_buf, sizeof g_buf);
            FILE *fp;
            snprintf(path, sizeof path, "%s/seed-%02d", argv[2], i);
            fp = fopen(path, "wb");
            if (fp == NULL || fwrite(g_buf, 1, n, fp) != n) {
                fprintf(stderr, "cannot write %s\n", path);
                return 1;
            }
            fclose(fp);
        }
        printf("wrote %d seeds to %s\n", fuzz_seed_count(), argv[2]);
        return 0;
    }
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--seeds") == 0) {
            int k;
            for (k = 0; k < fuzz_seed_count(); ++k) {
                const size_t n = fuzz_seed(k, g_buf, sizeof g_buf);
                LLVMFuzzerTestOneInput(g_buf, n);
                ++g_count;
            }
        } else {
            rc |= run_path(argv[i]);
        }
    }
    printf("replayed %lu inputs: no invariant violated\n", g_count);
    return rc;
}
