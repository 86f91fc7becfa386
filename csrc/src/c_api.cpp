// c_api.cpp: the only translation unit that implements pyins_core.h (the
// test hooks of pyins_core_testing.h are c_api_testing.cpp's).
//
// Every entry point checks its pointers, sizes and alignment before any C++
// runs, and reports through a negative status; nothing here can throw,
// allocate or print.
#include "pyins_core.h"

#include <cstdint>
#include <cstring>
#include <new>

#include "config.hpp"
#include "firmware.hpp"

using pyins::firmware::Firmware;

static_assert(sizeof(pyins_sample) == 8 * sizeof(double), "pyins_sample layout");
static_assert(sizeof(pyins_output) % 8 == 0, "pyins_output layout: arrays of records stay aligned");
static_assert(sizeof(pyins_nav) == 168, "pyins_nav layout: arrays of records stay aligned");
static_assert(alignof(Firmware) <= 16, "instance alignment");

namespace {

bool is_aligned(const void* p, size_t align) {
    return (reinterpret_cast<uintptr_t>(p) % align) == 0u;
}

/// The instance behind a handle, or a negative status.
int checked(const pyins_core* core, const Firmware** fw) {
    if (core == nullptr) {
        return PYINS_E_NULL;
    }
    if (!is_aligned(core, alignof(Firmware))) {
        return PYINS_E_MISALIGNED;
    }
    const Firmware* f = reinterpret_cast<const Firmware*>(core);
    if (f->magic() != pyins::firmware::kMagic) {
        return PYINS_E_NOT_INIT;
    }
    *fw = f;
    return PYINS_OK;
}

constexpr uint32_t kSnapMagic = 0x4E535950u;  // "PYSN" little-endian
constexpr uint32_t kSnapFormat = 9u;  // 2: sample-level fault state (seq, counters); 3: lever arm, coarse FIT;
                                      // 4: the navigation filter and the reference queue; 5: the DVL's
                                      // mounting in the configuration (ABI 0.16); 6: the damping
                                      // references of nav_mode DAMPED (ABI 0.17); 7: the navigation
                                      // filter's bias random walk and table-move model (ABI 0.18); 8: the
                                      // gyros' scale factors and misalignments as filter states (ABI 0.19);
                                      // 9: the coarse alignment under way (ABI 0.20)
constexpr size_t kSnapHeader = 24u;

/// CRC-32 (IEEE 802.3, reflected, bitwise: small, no table).
uint32_t crc32(const unsigned char* p, size_t n) {
    uint32_t c = 0xFFFFFFFFu;
    for (size_t i = 0; i < n; ++i) {
        c = c ^ p[i];
        for (int k = 0; k < 8; ++k) {
            c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
        }
    }
    return ~c;
}

void put_u32(unsigned char* p, uint32_t v) {
    p[0] = static_cast<unsigned char>(v);
    p[1] = static_cast<unsigned char>(v >> 8);
    p[2] = static_cast<unsigned char>(v >> 16);
    p[3] = static_cast<unsigned char>(v >> 24);
}

uint32_t get_u32(const unsigned char* p) {
    return static_cast<uint32_t>(p[0]) | (static_cast<uint32_t>(p[1]) << 8) |
           (static_cast<uint32_t>(p[2]) << 16) | (static_cast<uint32_t>(p[3]) << 24);
}

/// pyins_run_decimated and pyins_run_nav: one loop, the record written by
/// Firmware::output (outputs) or Firmware::nav_record (navs, when not
/// null) at the multiples of out_every. One function, not one per record
/// type: the Cortex-M7 text budget (docs/embedded.md) holds one copy.
int run_every(pyins_core* core, const pyins_sample* samples, size_t n, size_t out_every,
              pyins_output* outputs, pyins_nav* navs, size_t out_capacity, size_t* n_done, size_t* n_out) {
    if (n_done != nullptr) {
        *n_done = 0;
    }
    if (n_out != nullptr) {
        *n_out = 0;
    }
    const Firmware* cfw = nullptr;
    const int status = checked(core, &cfw);
    if (status != PYINS_OK) {
        return status;
    }
    if ((samples == nullptr && n > 0u) || (outputs == nullptr && navs == nullptr && out_capacity > 0u)) {
        return PYINS_E_NULL;
    }
    if (out_every == 0u) {
        return PYINS_E_BAD_ARG;
    }
    if (out_capacity < n / out_every + 1u) {
        return PYINS_E_BUFFER_TOO_SMALL;
    }
    Firmware* fw = const_cast<Firmware*>(cfw);
    const uint64_t every = static_cast<uint64_t>(out_every);
    size_t written = 0;
    // the next multiple of out_every after the current tick
    uint64_t next = (static_cast<uint64_t>(fw->tick()) / every + 1u) * every;
    for (size_t i = 0; i < n;) {
        // the plain ticks before the next record (Firmware::run_plain), in
        // one loop; one tick short of it when its record has no room. A
        // full record every tick leaves no run to take (step() at once); a
        // compact one every tick is written in run_plain's loop.
        const uint64_t stop = written == out_capacity ? next - 1u : next;
        size_t k = 0u;
        if (every == 1u && navs != nullptr) {
            // a compact record every tick: run_plain writes them as it goes
            // (as many as there is room for)
            const uint64_t room = static_cast<uint64_t>(out_capacity - written);
            const uint64_t headroom = static_cast<uint64_t>(INT64_MAX - fw->tick());
            k = fw->run_plain(samples + i, n - i,
                              room >= headroom ? INT64_MAX : fw->tick() + static_cast<int64_t>(room),
                              navs + written);
            if (k > 0u) {
                i = i + k;
                written = written + k;
                next = static_cast<uint64_t>(fw->tick()) + 1u;
                if (n_done != nullptr) {
                    *n_done = i;
                }
                if (n_out != nullptr) {
                    *n_out = written;
                }
                continue;
            }
        } else if (every > 1u) {
            k = fw->run_plain(samples + i, n - i,
                              stop > static_cast<uint64_t>(INT64_MAX) ? INT64_MAX : static_cast<int64_t>(stop),
                              nullptr);
        }
        if (k > 0u) {
            i = i + k;
        } else {
            if (written == out_capacity &&
                static_cast<uint64_t>(fw->tick() + fw->ticks_for(samples[i])) >= next) {
                // seq gaps passed more multiples than n / out_every + 1: stop
                // before the step whose record has no room
                return PYINS_E_BUFFER_TOO_SMALL;
            }
            const int s = fw->step(samples[i], nullptr);
            if (s < 0) {
                return s;
            }
            i = i + 1u;
        }
        if (n_done != nullptr) {
            *n_done = i;
        }
        // a multiple of out_every reached (or passed by a bridged gap)
        if (static_cast<uint64_t>(fw->tick()) >= next) {
            next = (static_cast<uint64_t>(fw->tick()) / every + 1u) * every;
            if (navs != nullptr) {
                fw->nav_record(&navs[written]);
            } else {
                fw->output(&outputs[written]);
            }
            written = written + 1u;
            if (n_out != nullptr) {
                *n_out = written;
            }
        }
    }
    return PYINS_OK;
}

}  // namespace

extern "C" {

uint32_t pyins_abi_version(void) {
    return (static_cast<uint32_t>(PYINS_ABI_VERSION_MAJOR) << 16) |
           static_cast<uint32_t>(PYINS_ABI_VERSION_MINOR);
}

const char* pyins_version_string(void) { return "0.1.0"; }

size_t pyins_core_size(void) { return sizeof(Firmware); }
size_t pyins_core_align(void) { return alignof(Firmware); }
size_t pyins_sizeof_config(void) { return sizeof(pyins_config); }
size_t pyins_sizeof_sample(void) { return sizeof(pyins_sample); }
size_t pyins_sizeof_output(void) { return sizeof(pyins_output); }
size_t pyins_sizeof_nav(void) { return sizeof(pyins_nav); }

int pyins_config_default(pyins_config* cfg) {
    if (cfg == nullptr) {
        return PYINS_E_NULL;
    }
    pyins::config::config_default(cfg);
    return PYINS_OK;
}

int pyins_config_check(const pyins_config* cfg) {
    if (cfg == nullptr) {
        return PYINS_E_NULL;
    }
    return pyins::config::config_check(*cfg);
}

int pyins_init(void* mem, size_t mem_size, const pyins_config* cfg) {
    if (mem == nullptr || cfg == nullptr) {
        return PYINS_E_NULL;
    }
    if (!is_aligned(mem, alignof(Firmware))) {
        return PYINS_E_MISALIGNED;
    }
    if (mem_size < sizeof(Firmware)) {
        return PYINS_E_MEM_TOO_SMALL;
    }
    const int status = pyins::config::config_check(*cfg);
    if (status != PYINS_OK) {
        return status;
    }
    // Every byte of the instance defined, padding included: a snapshot blob
    // (and its CRC-32) is then a function of the state alone.
    memset(mem, 0, sizeof(Firmware));
    Firmware* fw = new (mem) Firmware;  // placement new: no allocation
    fw->init(*cfg);
    return PYINS_OK;
}

int pyins_step(pyins_core* core, const pyins_sample* sample, pyins_output* out) {
    const Firmware* cfw = nullptr;
    const int status = checked(core, &cfw);
    if (status != PYINS_OK) {
        return status;
    }
    if (sample == nullptr || out == nullptr) {
        return PYINS_E_NULL;
    }
    return const_cast<Firmware*>(cfw)->step(*sample, out);
}

int pyins_run(pyins_core* core, const pyins_sample* samples, size_t n,
              pyins_output* outputs, size_t* n_done) {
    if (n_done != nullptr) {
        *n_done = 0;
    }
    const Firmware* cfw = nullptr;
    const int status = checked(core, &cfw);
    if (status != PYINS_OK) {
        return status;
    }
    if (samples == nullptr && n > 0u) {
        return PYINS_E_NULL;
    }
    Firmware* fw = const_cast<Firmware*>(cfw);
    for (size_t i = 0; i < n;) {
        if (outputs == nullptr) {
            // no records: the plain ticks in one loop (Firmware::run_plain)
            const size_t k = fw->run_plain(samples + i, n - i, INT64_MAX, nullptr);
            if (k > 0u) {
                i = i + k;
                if (n_done != nullptr) {
                    *n_done = i;
                }
                continue;
            }
        }
        const int s = fw->step(samples[i], outputs != nullptr ? &outputs[i] : nullptr);
        if (s < 0) {  // rejected; PYINS_W_* notices go on (the records carry them)
            return s;
        }
        i = i + 1u;
        if (n_done != nullptr) {
            *n_done = i;
        }
    }
    return PYINS_OK;
}


int pyins_run_decimated(pyins_core* core, const pyins_sample* samples, size_t n,
                        size_t out_every, pyins_output* outputs, size_t out_capacity,
                        size_t* n_done, size_t* n_out) {
    return run_every(core, samples, n, out_every, outputs, nullptr, out_capacity, n_done, n_out);
}

int pyins_run_nav(pyins_core* core, const pyins_sample* samples, size_t n, size_t out_every,
                  pyins_nav* navs, size_t out_capacity, size_t* n_done, size_t* n_out) {
    return run_every(core, samples, n, out_every, nullptr, navs, out_capacity, n_done, n_out);
}

int pyins_index_reset(pyins_core* core) {
    const Firmware* cfw = nullptr;
    const int status = checked(core, &cfw);
    if (status != PYINS_OK) {
        return status;
    }
    const_cast<Firmware*>(cfw)->index_reset();
    return PYINS_OK;
}

int pyins_push_ref(pyins_core* core, const pyins_ref* ref) {
    const Firmware* cfw = nullptr;
    const int status = checked(core, &cfw);
    if (status != PYINS_OK) {
        return status;
    }
    if (ref == nullptr) {
        return PYINS_E_NULL;
    }
    return const_cast<Firmware*>(cfw)->push_ref(*ref);
}

size_t pyins_snapshot_size(void) { return kSnapHeader + sizeof(Firmware); }

int pyins_snapshot(const pyins_core* core, void* buf, size_t buf_size) {
    const Firmware* fw = nullptr;
    const int status = checked(core, &fw);
    if (status != PYINS_OK) {
        return status;
    }
    if (buf == nullptr) {
        return PYINS_E_NULL;
    }
    if (buf_size < pyins_snapshot_size()) {
        return PYINS_E_SNAPSHOT_SIZE;
    }
    unsigned char* b = static_cast<unsigned char*>(buf);
    const unsigned char* payload = reinterpret_cast<const unsigned char*>(fw);
    memcpy(b + kSnapHeader, payload, sizeof(Firmware));
    put_u32(b, kSnapMagic);
    put_u32(b + 4, kSnapFormat);
    put_u32(b + 8, pyins_abi_version());
    put_u32(b + 12, static_cast<uint32_t>(sizeof(Firmware)));
    put_u32(b + 16, crc32(b + kSnapHeader, sizeof(Firmware)));
    put_u32(b + 20, 0u);
    return PYINS_OK;
}

int pyins_restore(void* mem, size_t mem_size, const void* buf, size_t buf_size) {
    if (mem == nullptr || buf == nullptr) {
        return PYINS_E_NULL;
    }
    if (!is_aligned(mem, alignof(Firmware))) {
        return PYINS_E_MISALIGNED;
    }
    if (mem_size < sizeof(Firmware)) {
        return PYINS_E_MEM_TOO_SMALL;
    }
    if (buf_size < kSnapHeader) {
        return PYINS_E_SNAPSHOT_SIZE;
    }
    const unsigned char* b = static_cast<const unsigned char*>(buf);
    if (get_u32(b) != kSnapMagic) {
        return PYINS_E_SNAPSHOT_CORRUPT;
    }
    if (get_u32(b + 4) != kSnapFormat || get_u32(b + 8) != pyins_abi_version()) {
        return PYINS_E_SNAPSHOT_VERSION;
    }
    if (get_u32(b + 12) != sizeof(Firmware) || buf_size != pyins_snapshot_size()) {
        return PYINS_E_SNAPSHOT_SIZE;
    }
    if (get_u32(b + 16) != crc32(b + kSnapHeader, sizeof(Firmware))) {
        return PYINS_E_SNAPSHOT_CORRUPT;
    }
    uint32_t magic;  // the instance's own marker, first member of Firmware
    memcpy(&magic, b + kSnapHeader + Firmware::magic_offset(), sizeof magic);
    if (magic != pyins::firmware::kMagic) {
        return PYINS_E_SNAPSHOT_CORRUPT;
    }
    // the payload holds no pointers (fixed-size values only): a byte copy is the state
    memcpy(mem, b + kSnapHeader, sizeof(Firmware));
    return PYINS_OK;
}

int pyins_get_output(const pyins_core* core, pyins_output* out) {
    const Firmware* fw = nullptr;
    const int status = checked(core, &fw);
    if (status != PYINS_OK) {
        return status;
    }
    if (out == nullptr) {
        return PYINS_E_NULL;
    }
    fw->output(out);
    return PYINS_OK;
}

int pyins_get_nav(const pyins_core* core, pyins_nav* nav) {
    const Firmware* fw = nullptr;
    const int status = checked(core, &fw);
    if (status != PYINS_OK) {
        return status;
    }
    if (nav == nullptr) {
        return PYINS_E_NULL;
    }
    fw->nav_record(nav);
    return PYINS_OK;
}

int pyins_get_motor_command(const pyins_core* core, pyins_motor_command* cmd) {
    const Firmware* fw = nullptr;
    const int status = checked(core, &fw);
    if (status != PYINS_OK) {
        return status;
    }
    if (cmd == nullptr) {
        return PYINS_E_NULL;
    }
    fw->motor_command(cmd);
    return PYINS_OK;
}

const char* pyins_status_str(int status) {
    switch (status) {
        case PYINS_OK: return "PYINS_OK: success";
        case PYINS_E_NULL: return "PYINS_E_NULL: a required pointer argument is NULL";
        case PYINS_E_MISALIGNED: return "PYINS_E_MISALIGNED: instance memory is not aligned to pyins_core_align()";
        case PYINS_E_MEM_TOO_SMALL: return "PYINS_E_MEM_TOO_SMALL: memory is smaller than pyins_core_size()";
        case PYINS_E_NOT_INIT: return "PYINS_E_NOT_INIT: the memory does not hold an initialised instance";
        case PYINS_E_SAMPLE_NONFINITE: return "PYINS_E_SAMPLE_NONFINITE: a sample field is NaN or Inf; sample rejected, state unchanged";
        case PYINS_E_BAD_ARG: return "PYINS_E_BAD_ARG: an argument is out of range (e.g. out_every == 0)";
        case PYINS_E_BUFFER_TOO_SMALL: return "PYINS_E_BUFFER_TOO_SMALL: the output buffer cannot hold the records asked for";
        case PYINS_E_CONFIG_RATE: return "PYINS_E_CONFIG_RATE: tick_hz must be 0 (default 100) or 1..10000";
        case PYINS_E_CONFIG_LAT: return "PYINS_E_CONFIG_LAT: latitude must be finite and within +-89.9 deg (ENU is singular at the poles)";
        case PYINS_E_CONFIG_LON: return "PYINS_E_CONFIG_LON: longitude must be finite and within +-720 deg";
        case PYINS_E_CONFIG_HEIGHT: return "PYINS_E_CONFIG_HEIGHT: height must be finite and within -1e4..1e5 m";
        case PYINS_E_CONFIG_VEL: return "PYINS_E_CONFIG_VEL: velocity must be finite and below 1e4 m/s per axis";
        case PYINS_E_CONFIG_ATT: return "PYINS_E_CONFIG_ATT: attitude angles, table angle and dvl_align_rad must be finite (dvl_align_rad at most pi long)";
        case PYINS_E_CONFIG_MODE: return "PYINS_E_CONFIG_MODE: vertical_mode must be PYINS_VERTICAL_HOLD or PYINS_VERTICAL_FREE";
        case PYINS_E_CONFIG_ALIGN_RATIO: return "PYINS_E_CONFIG_ALIGN_RATIO: coarse_ratio must be in (0, 1) (0 = default 1/2)";
        case PYINS_E_CONFIG_ALIGN_EARLY: return "PYINS_E_CONFIG_ALIGN_EARLY: first coarse output before enough data (coarse_ratio * first output < output interval)";
        case PYINS_E_CONFIG_ALIGN_LONG: return "PYINS_E_CONFIG_ALIGN_LONG: TRIAD coarse alignment longer than its storage allows (255 output intervals; FIT has no limit)";
        case PYINS_E_CONFIG_FINE: return "PYINS_E_CONFIG_FINE: fine_states must be 5, 8 or 12, the update interval positive, the correction known";
        case PYINS_E_CONFIG_NOISE: return "PYINS_E_CONFIG_NOISE: noise densities and initial sigmas must be positive and finite (0 = default)";
        case PYINS_E_CONFIG_INDEX_SCHEME: return "PYINS_E_CONFIG_INDEX_SCHEME: index_scheme is not one of the pyins_index_scheme values";
        case PYINS_E_CONFIG_INDEX_EMPTY: return "PYINS_E_CONFIG_INDEX_EMPTY: a custom indexing scheme needs 1..8 steps";
        case PYINS_E_CONFIG_INDEX_RATE: return "PYINS_E_CONFIG_INDEX_RATE: indexing rate and acceleration must be positive and finite";
        case PYINS_E_CONFIG_INDEX_DELTA: return "PYINS_E_CONFIG_INDEX_DELTA: the flexible threshold delta must be in (0, 1)";
        case PYINS_E_CONFIG_INDEX_STEP: return "PYINS_E_CONFIG_INDEX_STEP: an indexing step (stop ticks >= 1, known kind, non-zero finite angle), tolerance, jump or timeout out of range";
        case PYINS_E_SNAPSHOT_SIZE: return "PYINS_E_SNAPSHOT_SIZE: snapshot blob truncated or of the wrong length, or buffer too small";
        case PYINS_E_SNAPSHOT_VERSION: return "PYINS_E_SNAPSHOT_VERSION: snapshot of another format or ABI version";
        case PYINS_E_SNAPSHOT_CORRUPT: return "PYINS_E_SNAPSHOT_CORRUPT: snapshot magic or checksum wrong";
        case PYINS_E_CONFIG_ALIGN_TICKS: return "PYINS_E_CONFIG_ALIGN_TICKS: an alignment duration is negative, or the first output comes after its end";
        case PYINS_E_SAMPLE_SATURATED: return "PYINS_E_SAMPLE_SATURATED: an increment is at or beyond its saturation limit; sample rejected, state unchanged";
        case PYINS_E_CONFIG_SATURATION: return "PYINS_E_CONFIG_SATURATION: saturation limits must be positive and finite (0 = default 400 deg/s, 20 g per tick)";
        case PYINS_E_CONFIG_SEQ: return "PYINS_E_CONFIG_SEQ: seq_mode must be PYINS_SEQ_OFF or PYINS_SEQ_CHECK, seq_max_gap_ticks 1..100 (0 = default)";
        case PYINS_E_CONFIG_INDEX_SUMS: return "PYINS_E_CONFIG_INDEX_SUMS: index_sums must be PYINS_INDEX_SUMS_STOPS or PYINS_INDEX_SUMS_ALL";
        case PYINS_E_CONFIG_LEVER: return "PYINS_E_CONFIG_LEVER: lever_b_m, lever_p_m, dvl_lever_b_m and gnss_lever_b_m must be finite and at most 100 m long";
        case PYINS_E_CONFIG_COARSE_METHOD: return "PYINS_E_CONFIG_COARSE_METHOD: coarse_method must be PYINS_COARSE_TRIAD, PYINS_COARSE_FIT, PYINS_COARSE_EQ8 or PYINS_COARSE_FIT_VEL; PYINS_COARSE_FIT_VEL needs fine_ticks 0 and nav_mode not PYINS_NAV_UNDAMPED";
        case PYINS_E_CONFIG_INTEGRITY: return "PYINS_E_CONFIG_INTEGRITY: integrity_nis_window must be -1 (off), 0 (default) or positive, integrity_nis_max and integrity_coarse_rad finite and not negative";
        case PYINS_E_CONFIG_NAV: return "PYINS_E_CONFIG_NAV: nav_mode must be AUTO, UNDAMPED, DAMPED or INTEGRATED, nav_every_ticks 1..10 s, nav_gate positive and finite, nav_reject_limit >= 1, ref_max_latency_ticks 1..10 s (0 = default); nav_gyro_bias_rw 0..1e-6 rad/s/sqrt(s), nav_table_scale_sigma, nav_table_mis_sigma, nav_level_scale_sigma and nav_level_mis_sigma 0..0.01 (0 = not modelled)";
        case PYINS_E_REF_KIND: return "PYINS_E_REF_KIND: unknown reference kind, or one this build does not use (GNSS_POS, GNSS_VEL, SPEED_LOG, DVL bottom track, ZERO_VEL are used; a DVL with reserved != 0, water track, is not)";
        case PYINS_E_REF_VALUE: return "PYINS_E_REF_VALUE: a reference value is not finite (or a latitude beyond 90 deg), or its sigma is not finite and > 0; refused, state unchanged";
        case PYINS_E_REF_ORDER: return "PYINS_E_REF_ORDER: a reference older than the last one pushed, or older than ref_max_latency_ticks before the current tick; refused, state unchanged";
        case PYINS_E_REF_FUTURE: return "PYINS_E_REF_FUTURE: a reference more than 10 s ahead of the current tick; refused, state unchanged";
        case PYINS_E_REF_FULL: return "PYINS_E_REF_FULL: the reference queue (8) is full: step the samples its references wait for first; refused, state unchanged";
        case PYINS_E_REF_UNUSED: return "PYINS_E_REF_UNUSED: nav_mode is UNDAMPED (the firmware takes no references) or DAMPED (it takes no GNSS position)";
        case PYINS_W_SEQ_GAP: return "PYINS_W_SEQ_GAP: ticks missing before this sample: bridged (navigation) or alignment restarted; sample taken";
        case PYINS_W_SEQ_REPEAT: return "PYINS_W_SEQ_REPEAT: a sample already taken (seq repeated or behind): dropped, state unchanged";
        case PYINS_W_SEQ_LOST: return "PYINS_W_SEQ_LOST: seq jumped beyond the bridgeable gap: sample taken without bridging, sequence resynchronised";
        case PYINS_W_ENCODER_JUMP: return "PYINS_W_ENCODER_JUMP: the encoder changed by more than index_jump_rad per tick; sample taken";
        default: return "unknown pyins status code";
    }
}

}  // extern "C"
