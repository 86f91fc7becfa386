// firmware.hpp: the firmware instance: mode, one step per sample.
//
// Mirrored by pyins/reference/firmware.py. The instance takes a checked
// configuration (config.hpp) and resolves it; each sample is checked
// (finite, not saturated, in sequence), then advances one tick through the
// mode machine: coarse alignment, fine alignment, navigation with indexing.
#pragma once

#include <cstddef>
#include <cstdint>

#include "pyins_core.h"
#include "coarse_align.hpp"
#include "fine_filter.hpp"
#include "indexing.hpp"
#include "nav_filter.hpp"
#include "strapdown.hpp"
#include "types.hpp"
#include "units.hpp"

namespace pyins::firmware {

/// Firmware modes, as reported in pyins_output.mode (enum pyins_mode).
enum class Mode : int32_t {
    kIdle = PYINS_MODE_IDLE,
    kCoarseAlign = PYINS_MODE_COARSE_ALIGN,
    kFineAlign = PYINS_MODE_FINE_ALIGN,
    kNavigate = PYINS_MODE_NAVIGATE
};

/// A fine-alignment attitude is valid only once the filter's own heading
/// sigma is within 10' (the bound the integrity acceptance uses): from a
/// wide prior the heading wanders far while its sigma is still large
/// (docs/concepts.md, "Integrity": PSINS's real laser-gyro log).
inline constexpr double kValidHeadingSigma = 10.0 * kArcminToRad;
/// The navigation filter started on the coarse attitude (an alignment in
/// navigation: indexed, at anchor) is valid only once three times its
/// heading sigma is within those 10': its prior, fitted to the coarse
/// result, starts just inside 10' (9.8' at anchor), and at one sigma a
/// ship at anchor was called valid for 132 s while 10.0-10.8' off
/// (2026-12-06). The fine alignments' rule above is the older, looser one
/// (docs/concepts.md, "Alignment at anchor").
inline constexpr double kValidNavHeadingSigma = kValidHeadingSigma / 3.0;
/// The reference queue's depth (pyins_push_ref) and the kinds' slots.
inline constexpr int32_t kRefQueue = 8;
inline constexpr int32_t kRefKinds = 5;
/// A kind is in use while one of its references was applied within this [s].
inline constexpr int32_t kRefInUseS = 10;
/// Level damping by the speed log (docs/concepts.md, "At sea"): a
/// third-order network on each horizontal channel whose closed loop has the
/// poles (s + w_s)(s^2 + 2 zeta w_s s + w_s^2), w_s = sqrt(g / R) the
/// 84.4-min Schuler frequency: the Schuler period kept, its damping ratio
/// zeta, a real pole as fast, and no steady velocity error from a constant
/// gyro drift (damp_interval gives the gains).
inline constexpr double kDampingRatio = 0.707;
/// The course is straight while the bow's turn rate, low-passed with this
/// time constant [s], stays under kStraightRate [rad/s] (0.3 deg/s: a
/// ship's course change is 0.5-1 deg/s; the sea's yaw swing, ~1 deg/s at
/// ~0.1 Hz, is attenuated ~13x by the low-pass); damping waits kStraightS
/// seconds of it.
inline constexpr double kTurnTau = 20.0;
inline constexpr double kStraightRate = 0.3 * kPi / 180.0;
inline constexpr int32_t kStraightS = 10;
/// The current (and the ship's mean sideslip, the yaw swing's bias) is the
/// mean of v - v_log b over the first kCurrentReadings log readings used
/// (the velocity then is the alignment's or the references'), then, while
/// the velocity is known (GNSS velocity, a DVL or zero velocity in use), a
/// first-order low-pass over as many readings; held otherwise. Damping
/// waits for the mean: one reading would carry the yaw swing of the moment
/// (a few degrees at 8 m/s is 0.5 m/s across the bow).
inline constexpr int32_t kCurrentReadings = 60;
/// The log reads along the hull's fore-aft axis: a reading is taken only
/// while that axis's horizontal part (cos pitch) is above this (pitch under
/// 60 deg; a ship never pitches so: a log or an attitude that is wrong).
inline constexpr double kLogMinHorizontal = 0.5;
/// Bumpless return to INTEGRATED (docs/concepts.md, "At sea"): a
/// correction of more than kBlendMinM of position or kBlendMinMps of
/// velocity (what an outage drifted, not a fix's noise: the first fixes
/// after an outage, DAMPED or UNDAMPED take most of it) opens a window of
/// kBlendWindowS in which the filter's corrections move the navigation
/// solution as always but are added to an output offset, so that the
/// output does not jump; the offset then decays
/// with the time constant kBlendTau, its position part by at most
/// kBlendSpeed and its velocity part by at most kBlendAccel (the at-sea
/// bound for a switch: under 1 m and 1 cm/s from one second to the next).
/// Corrections at the fixes' noise are applied to the output at once, as
/// blending them would keep their noise in it after the filter has
/// averaged it out.
inline constexpr double kBlendMinM = 10.0;
inline constexpr double kBlendMinMps = 0.1;
inline constexpr int32_t kBlendWindowS = 10;
inline constexpr double kBlendTau = 60.0;      ///< [s]
inline constexpr double kBlendSpeed = 0.5;     ///< [m/s]
inline constexpr double kBlendAccel = 0.002;   ///< [m/s^2]
/// An offset below these is dropped [m], [m/s].
inline constexpr double kBlendDoneM = 1e-3;
inline constexpr double kBlendDoneMps = 1e-5;
/// "PYNS": marks memory that holds an initialised instance.
inline constexpr uint32_t kMagic = 0x50594E53u;

/// Sample-level fault counters (pyins_output.n_*), saturating at 2^32 - 1.
struct SampleCounts {
    uint32_t nonfinite;
    uint32_t saturated;
    uint32_t seq_gaps;
    uint32_t seq_bridged;
    uint32_t seq_repeats;
    uint32_t seq_lost;
    uint32_t encoder_jumps;
};

/// counter + n, saturating at 2^32 - 1 (a counter never wraps to look healthy).
inline void count(uint32_t* counter, uint32_t n) {
    *counter = n > 0xFFFFFFFFu - *counter ? 0xFFFFFFFFu : *counter + n;
}

/// How a sample's seq follows the last one taken (PYINS_SEQ_CHECK).
enum class SeqKind : int32_t { kNext = 0, kGap = 1, kRepeat = 2, kLost = 3 };
struct SeqStep {
    SeqKind kind;
    uint32_t missing;   ///< ticks missing before the sample (kGap, forward kLost)
};

class Firmware {
  public:
    /// Precondition: config_check(cfg) == PYINS_OK.
    void init(const pyins_config& cfg);

    /// One sample (docs/core.md, "Sample-level faults"): rejects a
    /// non-finite or saturated sample (state unchanged but for the fault
    /// bits and counters); with seq checking, drops a duplicate, bridges a
    /// short gap before taking the sample, resynchronises after a long one.
    /// Always fills *out (when not null) with the state after the call.
    /// Returns PYINS_OK, a PYINS_W_* notice or a negative status.
    int step(const pyins_sample& sample, pyins_output* out);

    /// step() without records for samples[0..n), up to the first that is
    /// not a plain tick or until tick() reaches tick_end; returns how many
    /// it took. Plain: in NAVIGATE (no alignment restart pending), a usable
    /// sample, the next seq (or seq not checked), the encoder within its
    /// jump limit: step() on it takes no branch but the tick's. The state
    /// after it is step()'s, bit for bit, without step()'s per-sample
    /// dispatch; the caller steps the sample that stopped it. With navs
    /// not null, each sample taken leaves its compact record there
    /// (navs[0..k), nav_record()'s bits): pyins_run_nav with a record
    /// every tick in one loop.
    size_t run_plain(const pyins_sample* samples, size_t n, int64_t tick_end, pyins_nav* navs);

    /// How many ticks stepping this sample would add to tick() (0: it would
    /// be rejected or dropped). Changes nothing.
    int64_t ticks_for(const pyins_sample& sample) const;

    /// The current state as an output record.
    void output(pyins_output* out) const;
    /// The current state as a compact record: output()'s fields of the
    /// same names, bit for bit (both are written from solution()).
    void nav_record(pyins_nav* nav) const;
    /// The motor command fields of output(), alone (pyins_get_motor_command).
    void motor_command(pyins_motor_command* cmd) const;

    /// Leave the indexing FAULT state (pyins_index_reset).
    void index_reset();

    /// One external reference (pyins_push_ref): checked whole, then applied
    /// now (its tick has passed: latency compensated) or queued for its tick.
    /// Returns PYINS_OK or a negative PYINS_E_REF_* status (state unchanged).
    int push_ref(const pyins_ref& ref);

    uint32_t magic() const { return magic_; }
    /// Byte offset of the marker inside the instance (for snapshots).
    static constexpr size_t magic_offset() { return 0; }
    int64_t tick() const { return tick_; }

  private:
    /// What output() and nav_record() both report, written into the
    /// record's own fields (no copy in between): the reference point's
    /// position and velocity, the IMU's and the ship's attitude
    /// quaternions [w, x, y, z], and whether the attitude is a solution
    /// (the record's state_flags).
    void solution(double* lat, double* lon, double* height, double vel_n[3], double quat_np[4],
                  double quat_nb[4], uint32_t* state_flags) const;
    /// nav_record()'s body (inlined into run_plain's loop on the host).
    void fill_nav(pyins_nav* nav) const;
    /// run_plain's loop, with (kNav) or without a compact record a tick.
    template <bool kNav>
    size_t plain_loop(const pyins_sample* samples, size_t n, int64_t tick_end, pyins_nav* navs);
    /// Classify a sample's seq against the last one taken.
    SeqStep seq_step(uint32_t seq) const;
    /// Finite and within the saturation limits.
    bool usable(const pyins_sample& sample) const;
    /// Advance one tick with increments taken as good: encoder unwrap, mode
    /// machine, alignment or navigation, indexing; tick + 1.
    void advance(const Vec3& dtheta_p, const Vec3& dv_p, double encoder);
    /// The encoder moved more than index_jump_rad per tick over missing + 1
    /// ticks since the last reading.
    bool encoder_jumped(double encoder, uint32_t missing) const;
    /// A sample's own tick, and the memory for the next one (the last
    /// increments and seq): step()'s end, and run_plain()'s loop.
    void take(uint32_t seq, const Vec3& dtheta_p, const Vec3& dv_p, double encoder);
    /// Bridge `missing` ticks before the sample (dtheta_p, dv_p, encoder):
    /// increments interpolated linearly between the last sample taken and
    /// this one, the encoder along the shortest turn between their readings.
    void bridge(int32_t missing, const Vec3& dtheta_p, const Vec3& dv_p, double encoder);
    /// Step 1's slow path, for a sample usable() refused: a non-finite one,
    /// else a saturated one (the limits are finite and > 0,
    /// config::config_check), rejected with its fault bit and counter.
    int reject_sample(const pyins_sample& sample, pyins_output* out);
    /// A rejected sample: sticky bit, counter, and an alignment restart.
    void reject(uint32_t fault_bit, uint32_t* counter);
    /// Leave coarse alignment for fine alignment or navigation.
    void end_coarse();
    /// The fine filter's heading sigma is within kValidHeadingSigma.
    bool fine_heading_known() const;
    /// A reference of any kind has been applied in navigation or met
    /// during the alignment.
    bool ref_aided() const;
    /// The navigation filter's heading sigma is within kValidNavHeadingSigma.
    bool nav_heading_known() const;
    /// Start / leave fine alignment.
    void start_fine();
    void end_fine();
    /// Correct the attitude by the fine filter's phi^ and reset phi^.
    void apply_fine_correction();
    /// The fine filter's attitude estimate phi^ [rad] (zero outside it).
    Vec3 fine_phi() const;
    /// Hold the static-base assumption of the alignment: site, at rest.
    void hold_at_site();
    /// Enter NAVIGATE: the indexing cycle starts from the measured angle.
    void start_navigation();
    /// The ship's attitude q_nb = q_np q_pb from the navigation solution and
    /// the encoder angle (q_pb = [cos(alpha/2), 0, 0, -sin(alpha/2)]).
    Quat ship_quat() const;
    /// The bow's horizontal direction in n (E, N; unit), from C_b^n's column
    /// 1; (0, 0) for a vertical bow. ``horizontal``, when given: the length
    /// of the column's horizontal part, the cosine of the bow's elevation
    /// (the ship's pitch).
    void bow_n(double* east, double* north, double* horizontal = nullptr) const;
    /// Sine and cosine of the IMU yaw psi_p = psi_b + alpha (docs/design.md
    /// §2) from the current solution, without taking the angle.
    void imu_yaw_sincos(double* sin_yaw_p, double* cos_yaw_p) const;
    /// Lever arm (docs/concepts.md, "Lever arms"): rate estimates at the end
    /// of this tick from its increments and the last tick's.
    void update_rates(const Vec3& dtheta_p, double dalpha);
    /// sin and cos of the encoder angle alpha, from its cached half-angle.
    void encoder_sincos(double* sin_alpha, double* cos_alpha) const;
    /// Rz(alpha)^T lever_b: the table centre from the reference point, in p [m].
    Vec3 lever_b_in_p() const;
    /// Rz(alpha)^T l: a vector l of the ship (b) in p.
    Vec3 b_in_p(const double* l) const;
    /// The GNSS antenna's velocity from the reference point, inertial
    /// derivative, in p: (w_ip^p - alpha' z) x Rz(alpha)^T gnss_lever_b [m/s].
    Vec3 gnss_lever_vel_p() const;
    /// r^p = Rz(alpha)^T lever_b + lever_p: reference point -> accelerometers, in p [m].
    Vec3 lever_p() const;
    /// u^p for the rates given (linear in them).
    Vec3 lever_vel_for(const Vec3& rate_p, double alpha_rate) const;
    /// u^p = d/dt (C_p^i r^p) in p: the accelerometers' velocity relative to
    /// the reference point, inertial derivative [m/s].
    Vec3 lever_vel_p() const;
    /// Earth-relative velocity of the accelerometers relative to the
    /// reference point, in n: C_p^n u^p - w_ie^n x C_p^n r^p [m/s].
    Vec3 lever_vel_e_n(const Mat3& mat_np) const;
    /// The reference point's position and velocity from the navigation
    /// state (the accelerometers') and the lever arm.
    void reference_point(double* lat, double* lon, double* height, Vec3* vel_n) const;
    /// One tick of fine alignment (static or moving base).
    void fine_tick(const Vec3& dtheta_p, const Vec3& dv_p);
    /// A static-base fine-alignment tick's hold: position and velocity at
    /// the site, and the lever arm's share taken out of the tick's specific
    /// force in n, *dv_sf_n [m/s].
    void hold_static_base(Vec3* dv_sf_n);
    /// Start the navigation filter (NAVIGATE, nav_mode not UNDAMPED).
    void start_nav_filter();
    /// The filter's linearisation point now.
    nav_filter::Motion nav_motion() const;
    /// Navigation filter work of a NAVIGATE tick, after the strapdown.
    void nav_tick(const Vec3& dv_sf_n, const Vec3& dtheta_c);
    /// The output offset's decay, once a tick in NAVIGATE (kBlendTau).
    void blend_tick();
    /// The output offset's position part in metres (E, N), by the Earth's
    /// radii where it was taken (blend_m_rad_: over the minutes of a blend
    /// they change by a part in 10^6; no radii computed a tick).
    void blend_offset_m(double* east, double* north) const;
    /// Once a filter interval in NAVIGATE: the course's turn rate and, in
    /// DAMPED, the level damping of the horizontal velocity by the log.
    void damp_interval();
    /// The reference point's velocity (E, N) [m/s] (the navigated point's
    /// without a lever arm).
    void ref_point_vel(double* east, double* north) const;
    void apply_log(const pyins_ref& ref, int32_t slot);
    /// A DVL reading (bottom track) as the reference point's velocity (E, N)
    /// [m/s] in *v_n, with the variances r[2] of its E and N components
    /// [m^2/s^2] (firmware_nav.cpp says how and what it leaves out).
    void dvl_n(const pyins_ref& ref, double v_n[2], double r[2]) const;
    /// How much faster than the reference point a point at the lever arm l
    /// (in b) moves, in n: C_b^n (w_eb^b x l) (rates_on_ keeps the rates).
    Vec3 point_vel_n(const Quat& q_nb, const double* l) const;
    /// A reference of kind slot + 1 failed its gate: counted; nav_reject_limit
    /// in a row put the kind out of use and set PYINS_FAULT_REF_REJECTED.
    void reject_ref(int32_t slot);
    /// A reference of kind slot + 1 passed its gate: counted, the kind in use.
    void use_ref(int32_t slot);
    /// A reference that came before navigation: counted as skipped; during
    /// an alignment, a velocity that says the site moves ends its integrity.
    void skip_ref(const pyins_ref& ref);
    /// Apply the references whose tick has come (tick_ just advanced).
    void refs_due();
    /// Gate and apply one reference now (lag: ticks since its tick).
    void apply_ref(const pyins_ref& ref, int64_t lag);
    /// The navigation mode in effect (pyins_output.nav_mode).
    int32_t nav_mode_now() const;
    /// The reference that damps (nav_mode DAMPED): the first in use in the
    /// override order GNSS velocity, the log (on a straight course, the
    /// current learnt), the DVL, zero velocity; 0 if none.
    int32_t damp_ref_kind() const;
    /// ref_in_use's bits.
    uint32_t refs_in_use() const;

    /// Put the navigation state on the accelerometers of a reference point
    /// at (lat, lon, height) moving with vel_n, with the current attitude.
    void place_imu(double lat, double lon, double height, const Vec3& vel_n);

    uint32_t magic_;
    Mode mode_;
    int64_t tick_;
    double dt_;                   ///< tick period [s]
    pyins_config cfg_;            ///< resolved configuration
    strapdown::Strapdown sd_;
    coarse_align::CoarseAlign coarse_;
    fine_filter::FineFilter fine_;  ///< the fine-alignment filter (5, 8 or 12 states)
    int32_t fine_tick_;           ///< samples taken in fine alignment
    int32_t align_restarts_;      ///< alignments restarted after a rejected sample
    bool gap_pending_;            ///< a sample was rejected during alignment
    uint32_t faults_;             ///< sticky pyins_fault_flag bits
    indexing::Params index_prm_;  ///< the configured cycle (started in NAVIGATE)
    indexing::Indexer idx_;
    bool att_valid_;              ///< attitude is a solution (not the configured guess)
    double table_angle_;          ///< unwrapped turntable angle alpha [rad]
    double encoder_;              ///< last encoder reading, in [0, 2 pi) [rad]
    double enc_sin_half_;         ///< sin(encoder_ / 2), kept with encoder_
    double enc_cos_half_;         ///< cos(encoder_ / 2)
    uint32_t seq_;                ///< seq of the last sample taken
    bool seq_valid_;              ///< a sample has been taken since init
    Vec3 last_dtheta_;            ///< increments of the last sample taken [rad]
    Vec3 last_dv_;                ///< [m/s]
    SampleCounts counts_;
    // Lever arm. Set only when one is configured; the state is then the
    // accelerometers', and the output the reference point's.
    int32_t has_lever_;           ///< 1: a lever arm is configured
    int32_t rate_count_;          ///< ticks advanced since init (saturates at 2)
    Vec3 rate_p_;                 ///< w_ip^p at the end of the last tick [rad/s]
    double alpha_rate_;           ///< table rate at the end of the last tick [rad/s]
    Vec3 prev_dtheta_;            ///< angle increment of the last tick advanced [rad]
    double prev_dalpha_;          ///< table angle change over the last tick advanced [rad]
    Vec3 lever_vel_n_;            ///< C_p^n u^p at the last fine-alignment tick [m/s]
    int32_t lever_refine_;        ///< 1: navigation started from the configured state last tick
    int32_t integrity_lost_;      ///< 1: an integrity test failed: the attitude is never valid again
    double coarse_wander_max_;    ///< sine of integrity_coarse_rad
    // Navigation at sea (nav_filter.hpp).
    int32_t nav_on_;              ///< 1: the navigation filter runs (NAVIGATE, not UNDAMPED)
    int32_t refq_head_;           ///< index of the oldest queued reference
    int32_t refq_count_;          ///< references queued
    int32_t rates_on_;            ///< 1: the rates are kept every tick (an IMU or a DVL lever arm)
    int64_t ref_last_tick_;       ///< tick of the last reference pushed (-1: none)
    pyins_ref refq_[kRefQueue];   ///< the queue, a ring
    nav_filter::NavFilter nav_;
    uint32_t n_ref_used_[kRefKinds];
    uint32_t n_ref_rejected_[kRefKinds];
    uint32_t n_ref_skipped_[kRefKinds];
    int32_t ref_reject_run_[kRefKinds];   ///< rejections in a row
    int32_t ref_out_[kRefKinds];          ///< 1: out of use (nav_reject_limit reached)
    int32_t reserved_ref_;                ///< (keeps the layout free of padding)
    int64_t ref_used_tick_[kRefKinds];    ///< tick of the last applied (-1: none)
    double nav_nis_[kRefKinds];
    // The frozen-receiver test (apply_ref): the last reference of each kind.
    uint32_t n_ref_stale_[kRefKinds];
    int32_t ref_seen_[kRefKinds];         ///< 1: a reference of the kind has been seen
    int64_t ref_seen_tick_[kRefKinds];    ///< its tick
    double ref_seen_value_[kRefKinds][2]; ///< its value[0], value[1]
    double ref_seen_vel_[kRefKinds][2];   ///< the reference point's velocity then (E, N) [m/s]
    // Level damping by the speed log (damp_interval, apply_log).
    double log_speed_;            ///< the last log reading used, its horizontal part [m/s] (apply_log)
    double current_n_[2];         ///< the water current learnt, v - v_log bow (E, N) [m/s]
    double bow_last_[2];          ///< the bow's direction at the last interval (E, N)
    double turn_rate_f_;          ///< the bow's turn rate, low-passed [rad/s]
    double damp_int_[2];          ///< the network's integrators, K3 int (v - v_ref) (E, N) [m/s]
    int32_t current_known_;       ///< log readings in current_n_'s mean (saturates at kCurrentReadings)
    int32_t straight_s_;          ///< seconds of straight course (saturates at kStraightS)
    int32_t bow_known_;           ///< 1: bow_last_ holds a value
    int32_t damp_on_;             ///< 1: the last interval damped
    /// nav_mode DAMPED: the reference point's ground velocity (E, N) [m/s]
    /// by the last reference used of each kind (the log's is v_log b + c)
    double damp_ref_[kRefKinds][2];
    // The bumpless return (kBlendWindowS; blend_tick, solution).
    double out_off_[4];           ///< added to the output: lat, lon [rad], v_E, v_N [m/s]
    double blend_m_rad_[2];       ///< metres a radian of lon, lat where the offset was taken (E, N)
    int32_t blend_window_;        ///< ticks left in which corrections go into out_off_
    int32_t blend_on_;            ///< 1: out_off_ is not zero
};

}  // namespace pyins::firmware
