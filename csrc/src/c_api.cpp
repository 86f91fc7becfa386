// c_api.cpp: the only translation unit that implements pyins_core.h (and,
// on the host with PYINS_TEST_HOOKS, pyins_core_testing.h).
//
// Every entry point checks its pointers, sizes and alignment before any C++
// runs, and reports through a negative status; nothing here can throw,
// allocate or print.
#include "pyins_core.h"

#include <cstdint>
#include <cstring>
#include <new>

#include "firmware.hpp"

using pyins::firmware::Firmware;

static_assert(sizeof(pyins_sample) == 8 * sizeof(double), "pyins_sample layout");
static_assert(sizeof(pyins_output) % 8 == 0, "pyins_output layout: arrays of records stay aligned");
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
constexpr uint32_t kSnapFormat = 3u;  // 2: sample-level fault state (seq, counters); 3: lever arm, coarse FIT
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

int pyins_config_default(pyins_config* cfg) {
    if (cfg == nullptr) {
        return PYINS_E_NULL;
    }
    pyins::firmware::config_default(cfg);
    return PYINS_OK;
}

int pyins_config_check(const pyins_config* cfg) {
    if (cfg == nullptr) {
        return PYINS_E_NULL;
    }
    return pyins::firmware::config_check(*cfg);
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
    const int status = pyins::firmware::config_check(*cfg);
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
    for (size_t i = 0; i < n; ++i) {
        const int s = fw->step(samples[i], outputs != nullptr ? &outputs[i] : nullptr);
        if (s < 0) {  // rejected; PYINS_W_* notices go on (the records carry them)
            return s;
        }
        if (n_done != nullptr) {
            *n_done = i + 1u;
        }
    }
    return PYINS_OK;
}

int pyins_run_decimated(pyins_core* core, const pyins_sample* samples, size_t n,
                        size_t out_every, pyins_output* outputs, size_t out_capacity,
                        size_t* n_done, size_t* n_out) {
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
    if ((samples == nullptr && n > 0u) || (outputs == nullptr && out_capacity > 0u)) {
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
    for (size_t i = 0; i < n; ++i) {
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
        if (n_done != nullptr) {
            *n_done = i + 1u;
        }
        // a multiple of out_every reached (or passed by a bridged gap)
        if (static_cast<uint64_t>(fw->tick()) >= next) {
            next = (static_cast<uint64_t>(fw->tick()) / every + 1u) * every;
            fw->output(&outputs[written]);
            written = written + 1u;
            if (n_out != nullptr) {
                *n_out = written;
            }
        }
    }
    return PYINS_OK;
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
        case PYINS_E_CONFIG_ATT: return "PYINS_E_CONFIG_ATT: attitude angles and table angle must be finite";
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
        case PYINS_E_CONFIG_LEVER: return "PYINS_E_CONFIG_LEVER: lever_b_m and lever_p_m must be finite and at most 100 m long";
        case PYINS_E_CONFIG_COARSE_METHOD: return "PYINS_E_CONFIG_COARSE_METHOD: coarse_method must be PYINS_COARSE_TRIAD or PYINS_COARSE_FIT";
        case PYINS_E_CONFIG_INTEGRITY: return "PYINS_E_CONFIG_INTEGRITY: integrity_nis_window must be -1 (off), 0 (default) or positive, integrity_nis_max and integrity_coarse_rad finite and not negative";
        case PYINS_W_SEQ_GAP: return "PYINS_W_SEQ_GAP: ticks missing before this sample: bridged (navigation) or alignment restarted; sample taken";
        case PYINS_W_SEQ_REPEAT: return "PYINS_W_SEQ_REPEAT: a sample already taken (seq repeated or behind): dropped, state unchanged";
        case PYINS_W_SEQ_LOST: return "PYINS_W_SEQ_LOST: seq jumped beyond the bridgeable gap: sample taken without bridging, sequence resynchronised";
        case PYINS_W_ENCODER_JUMP: return "PYINS_W_ENCODER_JUMP: the encoder changed by more than index_jump_rad per tick; sample taken";
        default: return "unknown pyins status code";
    }
}

}  // extern "C"

// ---------------------------------------------------------------------------
// Test hooks (pyins_core_testing.h), host only.
#if defined(PYINS_TEST_HOOKS) && PYINS_TEST_HOOKS
#include "attitude.hpp"
#include "earth.hpp"
#include "math_portable.hpp"
#include "pyins_core_testing.h"
#include "fine_align.hpp"
#include "indexing.hpp"
#include "strapdown.hpp"

namespace {

using pyins::Mat3;

template <int N>
void fine_run(const pyins::fine_align::Params& prm, const double* dv, size_t n, double* x_out,
              double* p_out) {
    pyins::fine_align::FineAlign<N> f;
    pyins::fine_align::init<N>(f, prm);
    for (size_t k = 0; k < n; ++k) {
        pyins::fine_align::step<N>(f, pyins::Vec3(dv[3 * k], dv[3 * k + 1], dv[3 * k + 2]));
    }
    for (int i = 0; i < N; ++i) {
        x_out[i] = f.x(i);
        for (int j = 0; j < N; ++j) {
            p_out[N * i + j] = f.p(i, j);
        }
    }
}
using pyins::Quat;
using pyins::Vec3;

Vec3 v3(const double* a) { return Vec3(a[0], a[1], a[2]); }
void put3(const Vec3& v, double* a) { a[0] = v(0); a[1] = v(1); a[2] = v(2); }
Quat q4(const double* a) { return Quat{a[0], a[1], a[2], a[3]}; }
void put4(const Quat& q, double* a) { a[0] = q.w; a[1] = q.x; a[2] = q.y; a[3] = q.z; }
Mat3 m9(const double* a) {
    Mat3 m;
    m << a[0], a[1], a[2], a[3], a[4], a[5], a[6], a[7], a[8];
    return m;
}
void put9(const Mat3& m, double* a) {
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            a[3 * i + j] = m(i, j);
        }
    }
}

}  // namespace

extern "C" {

double pyins_t_sin(double x) { return pyins::pmath::sin(x); }
double pyins_t_cos(double x) { return pyins::pmath::cos(x); }
double pyins_t_atan2(double y, double x) { return pyins::pmath::atan2(y, x); }
void pyins_t_sin_batch(const double* x, double* out, size_t n) {
    for (size_t i = 0; i < n; ++i) out[i] = pyins::pmath::sin(x[i]);
}
void pyins_t_cos_batch(const double* x, double* out, size_t n) {
    for (size_t i = 0; i < n; ++i) out[i] = pyins::pmath::cos(x[i]);
}
void pyins_t_atan2_batch(const double* y, const double* x, double* out, size_t n) {
    for (size_t i = 0; i < n; ++i) out[i] = pyins::pmath::atan2(y[i], x[i]);
}

void pyins_t_principal_radii(double sin_lat, double* rm, double* rn) {
    const pyins::earth::PrincipalRadii r = pyins::earth::principal_radii(sin_lat);
    *rm = r.rm;
    *rn = r.rn;
}
double pyins_t_normal_gravity(double sin_lat, double height) {
    return pyins::earth::normal_gravity(sin_lat, height);
}
void pyins_t_earth_at(double sin_lat, double cos_lat, double height, const double vel_n[3],
                      pyins_t_earth* out) {
    const pyins::earth::Earth e = pyins::earth::earth_at(sin_lat, cos_lat, height, v3(vel_n));
    out->sin_lat = e.sin_lat;
    out->cos_lat = e.cos_lat;
    out->tan_lat = e.tan_lat;
    out->rm_h = e.rm_h;
    out->rn_h = e.rn_h;
    put3(e.omega_ie_n, out->omega_ie_n);
    put3(e.omega_en_n, out->omega_en_n);
    put3(e.omega_in_n, out->omega_in_n);
    put3(e.gravity_n, out->gravity_n);
}
void pyins_t_position_rate(double sin_lat, double cos_lat, double height, const double vel_n[3],
                           double out[3]) {
    const pyins::earth::Earth e = pyins::earth::earth_at(sin_lat, cos_lat, height, v3(vel_n));
    put3(pyins::earth::position_rate(e, v3(vel_n)), out);
}

void pyins_t_quat_mul(const double p[4], const double q[4], double out[4]) {
    put4(pyins::attitude::quat_mul(q4(p), q4(q)), out);
}
void pyins_t_quat_normalize(const double q[4], double out[4]) {
    put4(pyins::attitude::quat_normalize(q4(q)), out);
}
void pyins_t_quat_to_mat(const double q[4], double m[9]) {
    put9(pyins::attitude::quat_to_mat(q4(q)), m);
}
void pyins_t_mat_to_quat(const double m[9], double q[4]) {
    put4(pyins::attitude::mat_to_quat(m9(m)), q);
}
void pyins_t_rotvec_to_quat(const double v[3], double q[4]) {
    put4(pyins::attitude::rotvec_to_quat(v3(v)), q);
}
void pyins_t_quat_to_rotvec(const double q[4], double v[3]) {
    put3(pyins::attitude::quat_to_rotvec(q4(q)), v);
}
void pyins_t_rot_z(double angle, double m[9]) { put9(pyins::attitude::rot_z(angle), m); }
void pyins_t_euler_to_mat(const double euler[3], double m[9]) {
    put9(pyins::attitude::euler_to_mat(v3(euler)), m);
}
void pyins_t_mat_to_euler(const double m[9], double euler[3]) {
    put3(pyins::attitude::mat_to_euler(m9(m)), euler);
}
void pyins_t_mat_orthonormalize(const double m[9], double out[9]) {
    put9(pyins::attitude::mat_orthonormalize(m9(m)), out);
}
double pyins_t_yaw_to_heading(double yaw) { return pyins::attitude::yaw_to_heading(yaw); }
double pyins_t_heading_to_yaw(double heading) { return pyins::attitude::heading_to_yaw(heading); }

void pyins_t_compensate(const double dtheta[3], const double dv[3], const double dtheta1[3],
                        const double dv1[3], const double dtheta2[3], const double dv2[3],
                        int32_t count, double phi[3], double dv_p[3]) {
    pyins::strapdown::History h;
    h.dtheta1 = v3(dtheta1);
    h.dv1 = v3(dv1);
    h.dtheta2 = v3(dtheta2);
    h.dv2 = v3(dv2);
    h.count = count;
    const pyins::strapdown::Compensated c = pyins::strapdown::compensate(v3(dtheta), v3(dv), h);
    put3(c.phi, phi);
    put3(c.dv_p, dv_p);
}

void pyins_t_strapdown_update(pyins_t_strapdown* s, const double dtheta_p[3], const double dv_p[3],
                              double dt) {
    pyins::strapdown::Strapdown sd;
    sd.nav.lat = s->lat;
    sd.nav.lon = s->lon;
    sd.nav.height = s->height;
    sd.nav.vel_n = v3(s->vel_n);
    sd.nav.quat_np = q4(s->quat_np);
    sd.hist.dtheta1 = v3(s->dtheta1);
    sd.hist.dv1 = v3(s->dv1);
    sd.hist.dtheta2 = v3(s->dtheta2);
    sd.hist.dv2 = v3(s->dv2);
    sd.hist.count = s->hist_count;
    sd.prev_dvel_n = v3(s->prev_dvel_n);
    sd.vertical = s->vertical == 1 ? pyins::strapdown::Vertical::kFree
                                   : pyins::strapdown::Vertical::kHold;
    sd.ref_height = s->ref_height;
    sd.ref_lon = s->lon;
    pyins::strapdown::update(sd, v3(dtheta_p), v3(dv_p), dt);
    s->lat = sd.nav.lat;
    s->lon = sd.nav.lon;
    s->height = sd.nav.height;
    put3(sd.nav.vel_n, s->vel_n);
    put4(sd.nav.quat_np, s->quat_np);
    put3(sd.hist.dtheta1, s->dtheta1);
    put3(sd.hist.dv1, s->dv1);
    put3(sd.hist.dtheta2, s->dtheta2);
    put3(sd.hist.dv2, s->dv2);
    s->hist_count = sd.hist.count;
    put3(sd.prev_dvel_n, s->prev_dvel_n);
}

int pyins_t_fine_align_run(int32_t states, const pyins_t_fine_params* p, const double* dv_sf_n,
                           size_t n, double* x_out, double* p_out) {
    pyins::fine_align::Params prm;
    prm.sin_lat = p->sin_lat;
    prm.cos_lat = p->cos_lat;
    prm.gravity = p->gravity;
    prm.dt = p->dt;
    prm.meas_every = p->meas_every;
    prm.gyro_arw = p->gyro_arw;
    prm.accel_vrw = p->accel_vrw;
    prm.sigma0_att[0] = p->sigma0_att[0];
    prm.sigma0_att[1] = p->sigma0_att[1];
    prm.sigma0_att[2] = p->sigma0_att[2];
    prm.sigma0_gyro = p->sigma0_gyro;
    prm.sigma0_accel = p->sigma0_accel;
    prm.nis_window = 0;   // the hook runs the filter alone, without the integrity test
    prm.nis_max = 0.0;
    if (states == 5) {
        fine_run<5>(prm, dv_sf_n, n, x_out, p_out);
    } else if (states == 8) {
        fine_run<8>(prm, dv_sf_n, n, x_out, p_out);
    } else {
        return -1;
    }
    return 0;
}

void pyins_t_coarse_pos_i(double t, double sin_lat, double cos_lat, double gravity, double out[3]) {
    put3(pyins::coarse_align::pos_i(t, sin_lat, cos_lat, gravity), out);
}

void pyins_t_coarse_fit_weights(double s, double* phi_a, double* phi_b) {
    pyins::coarse_align::fit_weights(s, phi_a, phi_b);
}

void pyins_t_coarse_solve_fit(const double* grid, int32_t n, double t_step, double sin_lat,
                              double cos_lat, double gravity, double m[9]) {
    pyins::Vec3 g[pyins::coarse_align::kHistLen];
    const int32_t k_max = n < pyins::coarse_align::kHistLen ? n : pyins::coarse_align::kHistLen;
    for (int32_t k = 0; k < k_max; ++k) {
        g[k] = v3(grid + 3 * k);
    }
    put9(pyins::coarse_align::solve_fit(g, k_max, t_step, sin_lat, cos_lat, gravity), m);
}

double pyins_t_coarse_rotation_sine(const double a[9], const double b[9]) {
    return pyins::coarse_align::rotation_sine(m9(a), m9(b));
}

int pyins_t_moving_align_run(const pyins_t_moving_params* p, const double* dv_sf_n, const double* z,
                             size_t n, double* x_out, double* p_out, double* nis_mean) {
    pyins::moving_align::Params prm;
    prm.sin_lat = p->sin_lat;
    prm.cos_lat = p->cos_lat;
    prm.rm_h = p->rm_h;
    prm.rn_h = p->rn_h;
    prm.dt = p->dt;
    prm.meas_every = p->meas_every;
    prm.gyro_arw = p->gyro_arw;
    prm.accel_vrw = p->accel_vrw;
    prm.pos_sigma = p->pos_sigma;
    prm.sigma0_att[0] = p->sigma0_att[0];
    prm.sigma0_att[1] = p->sigma0_att[1];
    prm.sigma0_att[2] = p->sigma0_att[2];
    prm.sigma0_vel = p->sigma0_vel;
    prm.sigma0_gyro = p->sigma0_gyro;
    prm.sigma0_accel = p->sigma0_accel;
    prm.nis_window = p->nis_window;
    prm.nis_max = p->nis_max;
    pyins::moving_align::MovingAlign m;
    pyins::moving_align::init(m, prm);
    int updates = 0;
    for (size_t k = 0; k < n; ++k) {
        if (pyins::moving_align::step(m, v3(dv_sf_n + 3 * k), z + 2 * k)) {
            updates = updates + 1;
        }
    }
    for (int i = 0; i < pyins::moving_align::kStates; ++i) {
        x_out[i] = m.x(i);
        for (int j = 0; j < pyins::moving_align::kStates; ++j) {
            p_out[pyins::moving_align::kStates * i + j] = m.p(i, j);
        }
    }
    *nis_mean = m.nis_mean;
    return updates;
}

void pyins_t_indexing_run(const pyins_t_index_params* p, double meas0, const double* meas,
                          const double* yaw_b, size_t n, pyins_t_index_out* out) {
    pyins::indexing::Params prm;
    prm.n_steps = p->n_steps;
    for (int i = 0; i < pyins::indexing::kMaxSteps; ++i) {
        prm.steps[i].stop_ticks = p->stop_ticks[i];
        prm.steps[i].kind = static_cast<pyins::indexing::Kind>(p->kind[i]);
        prm.steps[i].angle = p->angle[i];
    }
    prm.rate = p->rate;
    prm.accel = p->accel;
    prm.delta = p->delta;
    prm.max_flex = p->max_flex;
    prm.tolerance = p->tolerance;
    prm.jump = p->jump;
    prm.timeout_ticks = p->timeout_ticks;
    prm.sums = p->sums;
    prm.dt = p->dt;
    pyins::indexing::Indexer ix;
    pyins::indexing::init(ix, prm, meas0);
    for (size_t k = 0; k < n; ++k) {
        const double m = meas != nullptr ? meas[k] : ix.cmd_angle;
        pyins::indexing::update(ix, m, yaw_b[k] + m);
        out[k].state = static_cast<int32_t>(ix.state);
        out[k].step = ix.step;
        out[k].fault = static_cast<int32_t>(ix.fault);
        out[k].fallbacks = ix.fallbacks;
        out[k].cmd_angle = ix.cmd_angle;
        out[k].cmd_rate = ix.cmd_rate;
        out[k].a_c = ix.a_c;
        out[k].a_s = ix.a_s;
    }
}

int32_t pyins_t_index_preset(int32_t scheme, int32_t stop_ticks, pyins_t_index_params* out) {
    pyins::indexing::Step steps[pyins::indexing::kMaxSteps];
    const int32_t n = pyins::indexing::preset_steps(scheme, stop_ticks, steps);
    for (int32_t i = 0; i < n; ++i) {
        out->stop_ticks[i] = steps[i].stop_ticks;
        out->kind[i] = static_cast<int32_t>(steps[i].kind);
        out->angle[i] = steps[i].angle;
    }
    out->n_steps = n < 0 ? 0 : n;
    return n;
}

}  // extern "C"
#endif  // PYINS_TEST_HOOKS
