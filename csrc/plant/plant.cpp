// plant.cpp: the closed loop of pyins_plant.h. Host only; mirrored by
// pyins/sim/turntable.py (same per-tick order of operations).
#include "pyins_plant.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "angle.hpp"

namespace {

constexpr int kMaxNodes = 16;

/// The table's acceleration over one tick: reach the commanded rate within
/// the tick if the motor's limits allow (a rate loop with one-tick response).
double table_accel(const pyins_table_config& cfg, const pyins_plant_state& st, double dt) {
    double cmd = st.rate_cmd_rad_s;
    const bool active = cfg.fault != PYINS_TABLE_OK && st.tick >= cfg.fault_tick;
    if (active && cfg.fault == PYINS_TABLE_STALL) {
        cmd = 0.0;
    } else if (active && cfg.fault == PYINS_TABLE_REVERSE) {
        cmd = -cmd;
    }
    if (cmd > cfg.rate_max_rad_s) {
        cmd = cfg.rate_max_rad_s;
    } else if (cmd < -cfg.rate_max_rad_s) {
        cmd = -cfg.rate_max_rad_s;
    }
    double a = (cmd - st.rate_rad_s) / dt;
    if (a > cfg.accel_max_rad_s2) {
        a = cfg.accel_max_rad_s2;
    } else if (a < -cfg.accel_max_rad_s2) {
        a = -cfg.accel_max_rad_s2;
    }
    return a;
}

void apply_errors(const double m[9], const double bias[3], double quantum, const double* noise,
                  double dt, double res[3], const double in[3], double out[3]) {
    for (int i = 0; i < 3; ++i) {
        double v = m[3 * i] * in[0] + m[3 * i + 1] * in[1] + m[3 * i + 2] * in[2] + bias[i] * dt;
        if (noise != nullptr) {
            v = v + noise[i];
        }
        if (quantum > 0.0) {
            const double total = v + res[i];
            const double q = quantum * std::nearbyint(total / quantum);
            res[i] = total - q;
            v = q;
        }
        out[i] = v;
    }
}

/// The same double, bit for bit (-0.0 is not 0.0: its sine is -0.0).
bool same_bits(double a, double b) {
    uint64_t ua = 0;
    uint64_t ub = 0;
    std::memcpy(&ua, &a, sizeof ua);
    std::memcpy(&ub, &b, sizeof ub);
    return ua == ub;
}

}  // namespace

extern "C" int pyins_fil_run(pyins_core* core, pyins_plant_state* st, const pyins_table_config* table,
                             const pyins_imu_errors* err, const double* node_omega_b,
                             const double* node_force_b, const double* node_x, const double* node_w,
                             const double* node_sum_omega, const double* node_sum_force, int32_t n_nodes,
                             int64_t period, int64_t phase0, const double* gyro_noise, const double* accel_noise,
                             size_t n, double dt, size_t every,
                             pyins_output* outputs, pyins_plant_record* records, size_t capacity,
                             size_t* n_done, size_t* n_out) {
    if (n_done != nullptr) {
        *n_done = 0;
    }
    if (n_out != nullptr) {
        *n_out = 0;
    }
    if (core == nullptr || st == nullptr || table == nullptr || err == nullptr ||
        node_omega_b == nullptr || node_force_b == nullptr || node_x == nullptr || node_w == nullptr ||
        (capacity > 0 && (outputs == nullptr || records == nullptr))) {
        return PYINS_E_NULL;
    }
    if (n_nodes < 1 || n_nodes > kMaxNodes || period < 1 || phase0 < 0 || !(dt > 0.0) || every == 0) {
        return PYINS_E_BAD_ARG;
    }
    if (capacity < n / every + 1) {
        return PYINS_E_BUFFER_TOO_SMALL;
    }
    const double half = 0.5 * dt;
    size_t written = 0;
    pyins_motor_command cmd;
    double trig_alpha = std::numeric_limits<double>::quiet_NaN();  // no angle yet
    double trig_c = 1.0;
    double trig_s = 0.0;
    // cos and sin of the table angle, taken again only when it moved (a
    // table at rest has the same angle at every node and tick: the same bits)
    auto trig = [&](double alpha) {
        if (!same_bits(alpha, trig_alpha)) {
            trig_alpha = alpha;
            trig_c = std::cos(alpha);
            trig_s = std::sin(alpha);
        }
    };
    for (size_t k = 0; k < n; ++k) {
        const int64_t base = ((phase0 + static_cast<int64_t>(k)) % period) * n_nodes;
        const double a = table_accel(*table, *st, dt);
        double dtheta[3] = {0.0, 0.0, 0.0};
        double dv[3] = {0.0, 0.0, 0.0};
        if (st->rate_rad_s == 0.0 && a == 0.0) {
            // A table at rest all tick: one angle, so the rotation comes out
            // of the quadrature, Rz^T applied once to the weighted node sums
            // of the ship's rate and force (most ticks of a rotation scheme).
            trig(st->alpha_rad);
            double w_sum[3] = {0.0, 0.0, 0.0};
            double f_sum[3] = {0.0, 0.0, 0.0};
            if (node_sum_omega != nullptr && node_sum_force != nullptr) {
                // the caller's sums of this tick of the period (the same order, the same bits)
                const int64_t row = 3 * (base / n_nodes);
                for (int i = 0; i < 3; ++i) {
                    w_sum[i] = node_sum_omega[row + i];
                    f_sum[i] = node_sum_force[row + i];
                }
            } else {
                for (int32_t j = 0; j < n_nodes; ++j) {
                    const double* w_b = node_omega_b + 3 * (base + j);
                    const double* f_b = node_force_b + 3 * (base + j);
                    for (int i = 0; i < 3; ++i) {
                        w_sum[i] = w_sum[i] + node_w[j] * w_b[i];
                        f_sum[i] = f_sum[i] + node_w[j] * f_b[i];
                    }
                }
            }
            const double c = trig_c;
            const double s = trig_s;
            dtheta[0] = c * w_sum[0] + s * w_sum[1];
            dtheta[1] = -s * w_sum[0] + c * w_sum[1];
            dtheta[2] = w_sum[2];
            dv[0] = c * f_sum[0] + s * f_sum[1];
            dv[1] = -s * f_sum[0] + c * f_sum[1];
            dv[2] = f_sum[2];
        } else {
            for (int32_t j = 0; j < n_nodes; ++j) {
                const double tau = 0.5 * (1.0 + node_x[j]) * dt;
                const double alpha = st->alpha_rad + st->rate_rad_s * tau + 0.5 * a * tau * tau;
                const double alpha_dot = st->rate_rad_s + a * tau;
                trig(alpha);
                const double c = trig_c;
                const double s = trig_s;
                const double* w_b = node_omega_b + 3 * (base + j);
                const double* f_b = node_force_b + 3 * (base + j);
                // omega_ip^p = Rz(alpha)^T omega_ib^b + alpha_dot z;  f^p = Rz(alpha)^T f^b
                dtheta[0] = dtheta[0] + node_w[j] * (c * w_b[0] + s * w_b[1]);
                dtheta[1] = dtheta[1] + node_w[j] * (-s * w_b[0] + c * w_b[1]);
                dtheta[2] = dtheta[2] + node_w[j] * (w_b[2] + alpha_dot);
                dv[0] = dv[0] + node_w[j] * (c * f_b[0] + s * f_b[1]);
                dv[1] = dv[1] + node_w[j] * (-s * f_b[0] + c * f_b[1]);
                dv[2] = dv[2] + node_w[j] * f_b[2];
            }
        }
        for (int i = 0; i < 3; ++i) {
            dtheta[i] = half * dtheta[i];
            dv[i] = half * dv[i];
        }
        st->alpha_rad = st->alpha_rad + st->rate_rad_s * dt + 0.5 * a * dt * dt;
        st->rate_rad_s = st->rate_rad_s + a * dt;
        st->tick = st->tick + 1;

        pyins_sample sample;
        apply_errors(err->gyro_m, err->gyro_bias_rad_s, err->gyro_quantum_rad,
                     gyro_noise != nullptr ? gyro_noise + 3 * k : nullptr, dt, st->gyro_residual,
                     dtheta, sample.dtheta_p_rad);
        apply_errors(err->accel_m, err->accel_bias_mps2, err->accel_quantum_mps,
                     accel_noise != nullptr ? accel_noise + 3 * k : nullptr, dt, st->accel_residual, dv,
                     sample.dv_p_mps);
        double enc = st->alpha_rad;
        if (table->fault == PYINS_TABLE_JUMP && st->tick > table->fault_tick) {
            enc = enc + table->jump_rad;
        }
        enc = pyins::angle::wrap_two_pi(enc);
        if (table->encoder_lsb_rad > 0.0) {
            enc = table->encoder_lsb_rad * std::floor(enc / table->encoder_lsb_rad);
        }
        sample.table_angle_rad = enc;
        // the IMU's packet counter: the number of the tick the sample ends
        sample.seq = static_cast<uint32_t>(st->tick);
        sample.reserved = 0u;

        // one step without a record: the motor reads its command every tick,
        // the record is built only at the kept ticks (the same bits)
        const int status = pyins_run(core, &sample, 1, nullptr, nullptr);
        if (status < 0) {  // rejected; notices (e.g. an encoder jump) go on
            return status;
        }
        pyins_get_motor_command(core, &cmd);
        st->rate_cmd_rad_s = cmd.rate_rad_s;
        if (n_done != nullptr) {
            *n_done = k + 1;
        }
        if (static_cast<uint64_t>(st->tick) % static_cast<uint64_t>(every) == 0u) {
            pyins_get_output(core, &outputs[written]);
            records[written].tick = st->tick;
            records[written].alpha_rad = st->alpha_rad;
            records[written].rate_rad_s = st->rate_rad_s;
            records[written].encoder_rad = enc;
            written = written + 1;
            if (n_out != nullptr) {
                *n_out = written;
            }
        }
    }
    return PYINS_OK;
}
