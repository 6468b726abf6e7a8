// GSL odeiv2 stepping of one orbit: see integrator.hpp.

#include "hovering/flow/integrator.hpp"

#include <gsl/gsl_errno.h>

#include <algorithm>
#include <cmath>

#include "hovering/detail/common.hpp"

namespace hovering::detail {

namespace {

int gsl_rhs(double, const double y[], double dydt[], void* params) {
    const auto* F = static_cast<const Field*>(params);
    F->fn(*F, y, dydt);
    return GSL_SUCCESS;
}

}  // namespace

const gsl_odeiv2_step_type* stepper_type(const std::string& name) {
    if (name == "rk2") return gsl_odeiv2_step_rk2;
    if (name == "rk4") return gsl_odeiv2_step_rk4;
    if (name == "rkf45") return gsl_odeiv2_step_rkf45;
    if (name == "rkck") return gsl_odeiv2_step_rkck;
    if (name == "rk8pd") return gsl_odeiv2_step_rk8pd;
    if (name == "msadams") return gsl_odeiv2_step_msadams;
    bad("stepper must be one of rk2, rk4, rkf45, rkck, rk8pd (explicit one-step methods) or msadams "
        "(variable-order Adams multistep); the implicit steppers need a Jacobian the flow does not "
        "provide; got '" + name + "'");
}

Integrator::Integrator(const FlowSystem& s, const FlowOptions& o) : field_(s), atol_(o.atol), rtol_(o.rtol) {
    gsl_quiet();
    sys_ = gsl_odeiv2_system{&gsl_rhs, nullptr, std::size_t(field_.dim), &field_};
    const gsl_odeiv2_step_type* T = stepper_type(o.stepper);
    if (T == gsl_odeiv2_step_msadams) {
        driver_ = gsl_odeiv2_driver_alloc_standard_new(&sys_, T, 1e-3, o.atol, o.rtol, 1.0, 0.0);
        if (!driver_) throw std::bad_alloc();
        step_ = driver_->s;
        control_ = driver_->c;
        ext_ = gsl_odeiv2_step_alloc(gsl_odeiv2_step_rk8pd, std::size_t(field_.dim));
        if (!ext_) {
            gsl_odeiv2_driver_free(driver_);
            throw std::bad_alloc();
        }
    } else {
        step_ = gsl_odeiv2_step_alloc(T, std::size_t(field_.dim));
        control_ = gsl_odeiv2_control_standard_new(o.atol, o.rtol, 1.0, 0.0);
        if (!step_ || !control_) {
            if (step_) gsl_odeiv2_step_free(step_);
            if (control_) gsl_odeiv2_control_free(control_);
            throw std::bad_alloc();
        }
    }
}

Integrator::~Integrator() {
    if (driver_) {
        gsl_odeiv2_driver_free(driver_);
        gsl_odeiv2_step_free(ext_);
    } else {
        gsl_odeiv2_control_free(control_);
        gsl_odeiv2_step_free(step_);
    }
}

void Integrator::restart() {
    if (driver_) gsl_odeiv2_driver_reset(driver_);
    else gsl_odeiv2_step_reset(step_);
}

bool Integrator::advance(double* y, double* d, double* h, double hmax, double* h_done) {
    const int n = field_.dim;
    if (driver_) {
        const double t0 = t_ms_;
        *h = std::min(*h, hmax);
        const int st = gsl_odeiv2_evolve_apply(driver_->e, driver_->c, driver_->s, &sys_, &t_ms_, t0 + hmax, h, y);
        bool finite = st == GSL_SUCCESS;
        for (int i = 0; i < n; ++i) finite = finite && std::isfinite(y[i]);
        *h_done = t_ms_ - t0;
        if (!finite || !(*h_done > 0)) return false;
        field_(y, d);
        return true;
    }
    double y0[kMaxDim], err[kMaxDim], dout[kMaxDim];
    for (int i = 0; i < n; ++i) y0[i] = y[i];
    for (;;) {
        const double h0 = std::min(*h, hmax);
        const int st = gsl_odeiv2_step_apply(step_, 0.0, h0, y, err, d, dout, &sys_);
        bool finite = st == GSL_SUCCESS;
        for (int i = 0; i < n; ++i) finite = finite && std::isfinite(y[i]) && std::isfinite(err[i]);
        double hn = h0;
        const int adj = finite ? gsl_odeiv2_control_hadjust(control_, step_, y, err, dout, &hn) : GSL_ODEIV_HADJ_DEC;
        if (adj != GSL_ODEIV_HADJ_DEC) {
            for (int i = 0; i < n; ++i) d[i] = dout[i];
            *h_done = h0;
            *h = hn;
            return true;
        }
        for (int i = 0; i < n; ++i) y[i] = y0[i];
        *h = finite ? hn : 0.5 * h0;
        if (!(*h >= 1e-14 * hmax) || !std::isfinite(*h)) return false;  // the tolerance cannot be met
    }
}

void Integrator::prepare_extension(const double* y0, const double* d0, double h) {
    if (!driver_) return;
    // rk8pd's error ~ h^8: m = ratio^(1/8) substeps (rounded up) meet the tolerances.
    const int n = field_.dim;
    double y[kMaxDim], err[kMaxDim], din[kMaxDim];
    for (int i = 0; i < n; ++i) {
        y[i] = y0[i];
        din[i] = d0[i];
    }
    gsl_odeiv2_step_reset(ext_);
    gsl_odeiv2_step_apply(ext_, 0.0, h, y, err, din, nullptr, &sys_);
    double ratio = 0;
    for (int i = 0; i < n; ++i) ratio = std::max(ratio, std::fabs(err[i]) / (atol_ + rtol_ * std::fabs(y[i])));
    ext_sub_ = std::isfinite(ratio) ? std::min(64, std::max(1, int(std::ceil(1.2 * std::pow(ratio, 0.125))))) : 64;
}

void Integrator::exact(const double* y0, const double* d0, double dt, double* y1) {
    const int n = field_.dim;
    double err[kMaxDim], din[kMaxDim];
    for (int i = 0; i < n; ++i) {
        y1[i] = y0[i];
        din[i] = d0[i];
    }
    if (driver_) {
        gsl_odeiv2_step_reset(ext_);
        for (int k = 0; k < ext_sub_; ++k) {
            if (k > 0) field_(y1, din);
            gsl_odeiv2_step_apply(ext_, 0.0, dt / ext_sub_, y1, err, din, nullptr, &sys_);
        }
    } else {
        gsl_odeiv2_step_reset(step_);
        gsl_odeiv2_step_apply(step_, 0.0, dt, y1, err, din, nullptr, &sys_);
    }
}

}  // namespace hovering::detail
