// fine_filter.hpp: the firmware's one face of its fine-alignment filters,
// seed 001's static-base 5- and 8-state filters (fine_align.hpp) and the
// moving-base 12-state filter (moving_align.hpp), chosen by the filter size.
//
// The NumPy mirror holds the filter itself (pyins/reference/firmware.py,
// self.fine) and reads the fields the filters share by name; this holder is
// that one name in C++: a tag (the size: 0 before fine alignment, then 5, 8
// or 12), one dispatch point (visit) and the three filters kept as members
// (a fixed block, no heap, no virtual functions; a union would save the
// unused filters' ~2 KB of instance but would need the Eigen members'
// lifetimes handled by hand). Each accessor is the mirror's field or call
// of the same name, with the same floating-point operations in the same
// order. firmware.cpp branches on the filter's model (static_base) where
// the firmware's own work differs, never on its size.
#pragma once

#include <cstdint>

#include "angle.hpp"
#include "config.hpp"
#include "fine_align.hpp"
#include "math_portable.hpp"
#include "moving_align.hpp"
#include "strapdown.hpp"
#include "types.hpp"

namespace pyins::fine_filter {

/// Seed 001's static-base filters (5, 8 states): the firmware holds position
/// and velocity at the site and the filter measures the specific force in n;
/// R may take the coarse phase's measured noise and P0's attitude the fit to
/// the coarse result. Not the moving-base filter (12): its strapdown runs
/// free in the horizontal, it measures the reference point's offset from the
/// site, and its feedback (velocity and position too) runs in both
/// correction modes.
constexpr bool static_base(int32_t states) { return states == 5 || states == 8; }

/// The filters' parameters, filled once by the firmware: the static-base
/// filters' own (the fields every filter shares, and gravity) and the
/// moving-base filter's further ones.
struct Params {
    fine_align::Params base;
    double rm_h;             ///< R_M + h at the site [m]
    double rn_h;             ///< R_N + h at the site [m]
    double pos_sigma;        ///< R: the waves' horizontal displacement [m]
    double sigma0_vel;       ///< [m/s]
    double site_accel;       ///< the site's slow motion [m/s^2/sqrt(Hz)]; 0: rigid (moving_align.hpp)
};

/// What a coarse alignment leaves the static-base filters.
struct AfterCoarse {
    double measured_vrw;     ///< coarse_align::measured_vrw [(m/s)/sqrt(s)] (0: not measured)
    double seconds;          ///< the coarse alignment's length [s]
    double wander;           ///< its solution's wander over its last fifth (sine)
};

namespace detail {

// The per-filter calls behind FineFilter's accessors (overloads, one per
// filter type; the fields the filters share are read by name in visit).

template <int N>
bool step(fine_align::FineAlign<N>& f, const Vec3& dv_sf_n, const double* /*z_en*/) {
    return fine_align::step<N>(f, dv_sf_n);
}
inline bool step(moving_align::MovingAlign& m, const Vec3& dv_sf_n, const double* z_en) {
    return moving_align::step(m, dv_sf_n, z_en);
}

template <int N>
bool measure(const fine_align::FineAlign<N>& /*f*/) {
    return false;
}
inline bool measure(const moving_align::MovingAlign& m) { return moving_align::measure(m); }

template <int N>
void site_offset(const fine_align::FineAlign<N>& /*f*/, double /*lat*/, double /*lon*/, double /*lat0*/,
                 double /*lon0*/, double* /*z_en*/) {}
/// [E, N] offset of (lat, lon) from the site (lat0, lon0) on the site's radii [m].
inline void site_offset(const moving_align::MovingAlign& m, double lat, double lon, double lat0, double lon0,
                        double* z_en) {
    z_en[0] = angle::wrap_pi(lon - lon0) * m.prm.rn_h * m.prm.cos_lat;
    z_en[1] = (lat - lat0) * m.prm.rm_h;
}

template <int N>
Vec3 phi(const fine_align::FineAlign<N>& f) {
    return fine_align::phi<N>(f);
}
inline Vec3 phi(const moving_align::MovingAlign& m) {
    return Vec3(m.x(moving_align::kPhi), m.x(moving_align::kPhi + 1), m.x(moving_align::kPhi + 2));
}

template <int N>
double heading_variance(const fine_align::FineAlign<N>& f) {
    return f.p(fine_align::kPhi + 2, fine_align::kPhi + 2);
}
inline double heading_variance(const moving_align::MovingAlign& m) {
    return m.p(moving_align::kPhi + 2, moving_align::kPhi + 2);
}

template <int N>
void feedback(fine_align::FineAlign<N>& f, strapdown::NavState& /*nav*/) {
    fine_align::reset_phi<N>(f);
}
/// Velocity and position too (the moving-base filter's feedback), then
/// phi, dv, dp = 0.
inline void feedback(moving_align::MovingAlign& m, strapdown::NavState& nav) {
    const double* x = m.x.data();
    double sin_lat;
    double cos_lat;
    pmath::sincos(nav.lat, &sin_lat, &cos_lat);
    nav.vel_n(0) = nav.vel_n(0) - x[moving_align::kVel];
    nav.vel_n(1) = nav.vel_n(1) - x[moving_align::kVel + 1];
    nav.lat = nav.lat - x[moving_align::kPos + 1] / m.prm.rm_h;
    nav.lon = angle::wrap_pi(nav.lon - x[moving_align::kPos] / (m.prm.rn_h * cos_lat));
    moving_align::reset_feedback(m);
}

template <int N>
void record(const fine_align::FineAlign<N>& f, double kf_x[8], double kf_sigma[8]) {
    for (int i = 0; i < N; ++i) {
        kf_x[i] = f.x(i);
        kf_sigma[i] = pmath::sqrt(f.p(i, i));
    }
}
/// [phi, eps, nabla_E, nabla_N]: the 8-state filter's layout.
inline void record(const moving_align::MovingAlign& m, double kf_x[8], double kf_sigma[8]) {
    const int idx[8] = {moving_align::kPhi, moving_align::kPhi + 1, moving_align::kPhi + 2,
                        moving_align::kEps, moving_align::kEps + 1, moving_align::kEps + 2,
                        moving_align::kNabla, moving_align::kNabla + 1};
    for (int i = 0; i < 8; ++i) {
        kf_x[i] = m.x(idx[i]);
        kf_sigma[i] = pmath::sqrt(m.p(idx[i], idx[i]));
    }
}

}  // namespace detail

class FineFilter {
    // (first: the accessors below deduce their return type from it)
    /// The one dispatch on the filter size (Self: FineFilter or const FineFilter).
    template <class Self, class Fn>
    static decltype(auto) visit(Self& self, Fn&& fn) {
        switch (self.states_) {
            case 5:
                return fn(self.fine5_);
            case 8:
                return fn(self.fine8_);
            default:
                return fn(self.moving_);
        }
    }

  public:
    /// No filter yet (states() == 0).
    void clear() {
        states_ = 0;
        vrw_ = 0.0;
    }

    /// Build the filter of `states` (5, 8 or 12; config-checked) from the
    /// shared parameters; after_coarse not null when a coarse alignment ran.
    /// The static-base filters then take the measured noise for R when it
    /// is larger than the configured density (fine_noise MEASURED;
    /// coarse_align.hpp, "Noise") and fit each attitude sigma left 0 to the
    /// coarse result (fine_align::sigma0_after_coarse, capped at the
    /// default). The moving-base filter keeps the configured values (its
    /// default attitude sigma is already the fit, with margin: config.hpp)
    /// and, when the site moves (site_accel > 0), adds what the site motion
    /// and the wander leave the coarse result (moving_align::sigma0_after_coarse).
    void init(int32_t states, const Params& prm, const AfterCoarse* after_coarse) {
        states_ = states;
        vrw_ = 0.0;
        const fine_align::Params& base = prm.base;
        if (states == 12) {
            moving_align::Params mp;
            mp.sin_lat = base.sin_lat;
            mp.cos_lat = base.cos_lat;
            mp.rm_h = prm.rm_h;
            mp.rn_h = prm.rn_h;
            mp.dt = base.dt;
            mp.meas_every = base.meas_every;
            mp.gyro_arw = base.gyro_arw;
            mp.accel_vrw = base.accel_vrw;
            mp.pos_sigma = prm.pos_sigma;
            mp.site_accel = prm.site_accel;
            mp.sigma0_att[0] = base.sigma0_att[0];
            mp.sigma0_att[1] = base.sigma0_att[1];
            mp.sigma0_att[2] = base.sigma0_att[2];
            mp.sigma0_vel = prm.sigma0_vel;
            mp.sigma0_gyro = base.sigma0_gyro;
            mp.sigma0_accel = base.sigma0_accel;
            mp.nis_window = base.nis_window;
            mp.nis_max = base.nis_max;
            if (after_coarse != nullptr) {
                moving_align::sigma0_after_coarse(mp, after_coarse->seconds, after_coarse->wander, base.gravity);
            }
            moving_align::init(moving_, mp);
            return;
        }
        fine_align::Params fp = base;
        if (after_coarse != nullptr) {
            if (after_coarse->measured_vrw > fp.accel_vrw) {
                fp.accel_vrw = after_coarse->measured_vrw;
            }
            // capped at the default (copied: the inline table's address is not taken)
            const double cap[3] = {config::kDefaultFineSigmaAtt[0], config::kDefaultFineSigmaAtt[1],
                                   config::kDefaultFineSigmaAtt[2]};
            fine_align::sigma0_after_coarse(fp, after_coarse->seconds, after_coarse->wander, cap);
        }
        vrw_ = fp.accel_vrw;
        if (states == 8) {
            fine_align::init<8>(fine8_, fp);
        } else {
            fine_align::init<5>(fine5_, fp);
        }
    }

    /// 0 before fine alignment starts, then 5, 8 or 12 (the record's kf_states).
    int32_t states() const { return states_; }
    /// fine_filter::static_base(states()).
    bool static_base() const { return fine_filter::static_base(states_); }
    /// The static-base filter's R density [(m/s)/sqrt(s)] (the record's
    /// fine_vrw); 0 for the moving-base filter and before fine alignment.
    double vrw() const { return static_base() ? vrw_ : 0.0; }

    // The rest: precondition states() != 0, except nis_mean() and record().

    /// True when this tick ends a moving-base interval: step() then reads
    /// z_en (site_offset's). False for the static-base filters.
    bool measure() const {
        return visit(*this, [](const auto& k) { return detail::measure(k); });
    }
    /// z_en: the [E, N] offset of (lat, lon) from the site (lat0, lon0) [m]
    /// (moving base; unchanged for the static-base filters).
    void site_offset(double lat, double lon, double lat0, double lon0, double z_en[2]) const {
        visit(*this, [&](const auto& k) { detail::site_offset(k, lat, lon, lat0, lon0, z_en); });
    }
    /// One tick: dv_sf_n is the tick's specific-force velocity increment in
    /// n' [m/s]; z_en the site offset (read by the moving-base filter when
    /// measure() said so). True when a measurement update happened.
    bool step(const Vec3& dv_sf_n, const double z_en[2]) {
        return visit(*this, [&](auto& k) { return detail::step(k, dv_sf_n, z_en); });
    }
    /// P positive definite (diagonal check) after every step so far.
    bool healthy() const {
        return visit(*this, [](const auto& k) { return k.healthy; });
    }
    /// No NIS window beyond nis_max so far.
    bool consistent() const {
        return visit(*this, [](const auto& k) { return k.consistent; });
    }
    /// Mean NIS of the last complete window (0 before one, and without a filter).
    double nis_mean() const {
        if (states_ == 0) {
            return 0.0;
        }
        return visit(*this, [](const auto& k) { return k.nis_mean; });
    }
    /// Complete NIS windows so far.
    int32_t nis_windows() const {
        return visit(*this, [](const auto& k) { return k.nis_windows; });
    }
    /// P of phi_U [rad^2].
    double heading_variance() const {
        return visit(*this, [](const auto& k) { return detail::heading_variance(k); });
    }
    /// The attitude error estimate phi^ (E, N, U) [rad].
    Vec3 phi() const {
        return visit(*this, [](const auto& k) { return detail::phi(k); });
    }
    /// After phi^ has been fed back into the attitude: phi^ = 0; the
    /// moving-base filter also corrects nav's horizontal velocity and
    /// position by dv^, dp^ and zeroes them.
    void feedback(strapdown::NavState& nav) {
        visit(*this, [&](auto& k) { detail::feedback(k, nav); });
    }
    /// The record's kf_x and kf_sigma (8 each, zeroed by the caller): the
    /// state and the square roots of P's diagonal in the 8-state layout
    /// (the 5-state filter fills the first 5; nothing without a filter).
    void record(double kf_x[8], double kf_sigma[8]) const {
        if (states_ == 0) {
            return;
        }
        visit(*this, [&](const auto& k) { detail::record(k, kf_x, kf_sigma); });
    }

  private:
    int32_t states_;          ///< 0 until fine alignment starts, then 5, 8 or 12
    double vrw_;              ///< the static-base filter's R density [(m/s)/sqrt(s)]
    fine_align::FineAlign<5> fine5_;
    fine_align::FineAlign<8> fine8_;
    moving_align::MovingAlign moving_;
};

}  // namespace pyins::fine_filter
