/* fuzz_c_api.h: the fuzz target of the pyins C ABI (fuzz_c_api.c), shared by
 * the libFuzzer build (tools/fuzz.sh) and the replay driver (replay_main.c)
 * that ctest runs on tests/fuzz/regressions/ and tests/fuzz/corpus/. */
#ifndef PYINS_FUZZ_C_API_H
#define PYINS_FUZZ_C_API_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* libFuzzer's entry point: one input, every invariant checked (abort on a
 * violation, after printing which). Returns 0. */
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* Built-in seed k (0 <= k < fuzz_seed_count()) written into buf (cap bytes);
 * returns its length. Seeds are built from valid configurations and
 * operation sequences (snapshots are taken and mutated by the target itself,
 * so the seeds stay valid across ABI versions). */
size_t fuzz_seed(int k, uint8_t *buf, size_t cap);
int fuzz_seed_count(void);

#ifdef __cplusplus
}
#endif

#endif
