// The only file of phytocal that touches Ceres Solver: see ceres_bridge.h.
//
// Every extern "C" function catches all exceptions and returns an error
// code, and every size and index is validated before Ceres sees it (Ceres
// CHECK failures abort the process).

#include "fit/engine/ceres_module_internal.h"

#include <ceres/ceres.h>
#include <ceres/dynamic_numeric_diff_cost_function.h>
#include <glog/logging.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <memory>
#include <mutex>
#include <new>
#include <string>
#include <vector>

namespace {

struct Parameter {
    double lower = -INFINITY;
    double upper = INFINITY;
    double scale = 1.0;
    bool fixed = false;
};

struct Block {
    size_t m = 0;
    std::vector<size_t> index;  // global parameter indices
    phc_residual_fn fn = nullptr;
    phc_derivatives derivs = PHC_DERIV_ANALYTIC;
    phc_loss_kind loss = PHC_LOSS_NONE;
    double loss_scale = 1.0;
    void *user_data = nullptr;
};

// Shared by all cost functions of one solve: a fatal callback error stops it.
struct SolveState {
    std::atomic<bool> fatal{false};
    std::atomic<int> fatal_code{0};
};

// Maps the block's scaled parameters u to physical x = u * scale.
static void unscale(const Block &b, const std::vector<Parameter> &params,
                    double const *const *u, double *x)
{
    for (size_t j = 0; j < b.index.size(); ++j)
        x[j] = u[j][0] * params[b.index[j]].scale;
}

static bool all_finite(const double *v, size_t n)
{
    for (size_t i = 0; i < n; ++i)
        if (!std::isfinite(v[i]))
            return false;
    return true;
}

// Calls the user's callback; false (step rejected) for a domain failure or
// non-finite output, and records fatal errors in the solve state.
static bool call_block(const Block &b, const double *x, double *r, double *jac,
                       SolveState *state)
{
    if (state && state->fatal.load())
        return false;
    const int rc = b.fn(x, r, jac, b.user_data);
    if (rc < 0) {
        if (state) {
            state->fatal_code.store(rc);
            state->fatal.store(true);
        }
        return false;
    }
    if (rc > 0)
        return false;
    if (!all_finite(r, b.m))
        return false;
    if (jac && !all_finite(jac, b.m * b.index.size()))
        return false;
    return true;
}

// A block with analytic derivatives, in scaled coordinates.
//
// Ceres's trust-region loop asks for the residuals alone at a candidate
// point and, when it accepts the step, for the residuals and the Jacobian at
// that same point (TrustRegionMinimizer: the candidate's cost, then
// EvaluateGradientAndJacobian).  A callback that fills the Jacobian computes
// the residuals on the way (curve expressions: one forward and one reverse
// sweep), so while steps are being accepted the candidate is evaluated with
// its Jacobian once and the accepted point is served from that evaluation:
// one model run per accepted step instead of two.  After a rejected step
// (the last candidate's Jacobian never asked for) candidates are evaluated
// without the Jacobian again until one is accepted, so a model whose
// Jacobian costs many runs (finite differences inside the kind) pays it for
// at most one rejected candidate in a row.  Served values are the same
// numbers the callback returned: the results do not change.
class AnalyticCost final : public ceres::CostFunction {
  public:
    // one_block: the block's k parameters are one Ceres parameter block of
    // size k (one_parameter_block) instead of k blocks of size 1.
    AnalyticCost(const Block &b, const std::vector<Parameter> &params, SolveState *state, bool one_block = false)
        : b_(b), params_(params), state_(state), one_block_(one_block), scale_(b.index.size()), x_(b.index.size()),
          key_(b.index.size()), r_(b.m), jac_(b.m * b.index.size())
    {
        for (size_t j = 0; j < b.index.size(); ++j)
            scale_[j] = params[b.index[j]].scale;
        set_num_residuals(static_cast<int>(b.m));
        if (one_block)
            mutable_parameter_block_sizes()->push_back(static_cast<int>(b.index.size()));
        else
            for (size_t j = 0; j < b.index.size(); ++j)
                mutable_parameter_block_sizes()->push_back(1);
    }

    bool Evaluate(double const *const *u, double *residuals, double **jacobians) const override
    {
        std::lock_guard<std::mutex> lock(mutex_);
        const size_t k = b_.index.size();
        // the scaled parameters u_j, as one block or k blocks
        const auto uj = [&](size_t j) { return one_block_ ? u[0][j] : u[j][0]; };
        bool same = has_key_;
        for (size_t j = 0; same && j < k; ++j)
            same = key_[j] == uj(j);
        if (!jacobians) {
            if (same) {  // asked twice at one point
                std::copy(r_.begin(), r_.end(), residuals);
                return true;
            }
            if (pending_)  // the last candidate's Jacobian was never asked for: rejected
                with_jacobian_ = false;
            has_key_ = has_jac_ = pending_ = false;
            unscale_u(uj);
            bool ok = false, jac_ok = false;
            if (with_jacobian_)
                ok = jac_ok = call_block(b_, x_.data(), r_.data(), jac_.data(), state_);
            if (!ok)  // also when only the Jacobian was not finite
                ok = call_block(b_, x_.data(), r_.data(), nullptr, state_);
            if (!ok)
                return false;
            for (size_t j = 0; j < k; ++j)
                key_[j] = uj(j);
            has_key_ = pending_ = true;
            has_jac_ = jac_ok;
            std::copy(r_.begin(), r_.end(), residuals);
            return true;
        }
        if (same && pending_)  // the candidate was accepted
            with_jacobian_ = true;
        pending_ = false;
        if (!(same && has_jac_)) {
            has_key_ = has_jac_ = false;
            unscale_u(uj);
            if (!call_block(b_, x_.data(), r_.data(), jac_.data(), state_))
                return false;
            for (size_t j = 0; j < k; ++j)
                key_[j] = uj(j);
            has_key_ = has_jac_ = true;
        }
        std::copy(r_.begin(), r_.end(), residuals);
        // d r / d u_j = d r / d x_j * scale_j; Ceres wants per-block m x 1,
        // or for one block m x k row-major: the callback's own layout.
        if (one_block_) {
            if (jacobians[0])
                for (size_t i = 0; i < b_.m; ++i)
                    for (size_t j = 0; j < k; ++j)
                        jacobians[0][i * k + j] = jac_[i * k + j] * scale_[j];
            return true;
        }
        for (size_t j = 0; j < k; ++j) {
            if (!jacobians[j])
                continue;
            const double s = scale_[j];
            for (size_t i = 0; i < b_.m; ++i)
                jacobians[j][i] = jac_[i * k + j] * s;
        }
        return true;
    }

  private:
    // x_ = the physical parameters of the scaled ones uj(j).
    template <class U> void unscale_u(const U &uj) const
    {
        for (size_t j = 0; j < b_.index.size(); ++j)
            x_[j] = uj(j) * scale_[j];
    }

    const Block &b_;
    const std::vector<Parameter> &params_;
    SolveState *state_;
    bool one_block_;
    std::vector<double> scale_;  // scale_j of the block's parameters
    // The last evaluation (physical x_, its scaled key_, residuals r_ and
    // Jacobian jac_ as the callback fills it, m x k row-major) and the
    // prediction state; guarded by mutex_ (Ceres may evaluate blocks on
    // several threads).
    mutable std::mutex mutex_;
    mutable std::vector<double> x_, key_, r_, jac_;
    mutable bool has_key_ = false, has_jac_ = false;
    mutable bool pending_ = false;        // key_ is a candidate whose Jacobian has not been asked for
    mutable bool with_jacobian_ = true;   // evaluate candidates with their Jacobian
};

// Residuals only, for Ceres's numerical differentiation.
class ResidualFunctor {
  public:
    ResidualFunctor(const Block &b, const std::vector<Parameter> &params, SolveState *state)
        : b_(b), params_(params), state_(state) {}

    bool operator()(double const *const *u, double *residuals) const
    {
        std::vector<double> x(b_.index.size());
        unscale(b_, params_, u, x.data());
        return call_block(b_, x.data(), residuals, nullptr, state_);
    }

  private:
    const Block &b_;
    const std::vector<Parameter> &params_;
    SolveState *state_;
};

static std::unique_ptr<ceres::CostFunction>
make_block_cost(const Block &b, const std::vector<Parameter> &params, SolveState *state)
{
    if (b.derivs == PHC_DERIV_ANALYTIC)
        return std::make_unique<AnalyticCost>(b, params, state);
    ceres::NumericDiffOptions nd;
    std::unique_ptr<ceres::DynamicCostFunction> cost;
    if (b.derivs == PHC_DERIV_RIDDERS) {
        cost = std::make_unique<ceres::DynamicNumericDiffCostFunction<ResidualFunctor, ceres::RIDDERS>>(
            new ResidualFunctor(b, params, state), ceres::TAKE_OWNERSHIP, nd);
    } else {
        // Optimal central step for double precision is about eps^(1/3) ~ 6e-6
        // relative; the scaled parameters are O(1).
        nd.relative_step_size = 6e-6;
        cost = std::make_unique<ceres::DynamicNumericDiffCostFunction<ResidualFunctor, ceres::CENTRAL>>(
            new ResidualFunctor(b, params, state), ceres::TAKE_OWNERSHIP, nd);
    }
    for (size_t j = 0; j < b.index.size(); ++j)
        cost->AddParameterBlock(1);
    cost->SetNumResiduals(static_cast<int>(b.m));
    return cost;
}

// Robust losses act on each residual, but Ceres applies a loss to a residual
// block's squared norm.  So a data set with a loss becomes m one-residual
// blocks that share one evaluation of the data set through this cache (the
// model is evaluated once per parameter vector, not m times).
class SharedEvaluation {
  public:
    SharedEvaluation(ceres::CostFunction *inner, size_t m, size_t k)
        : inner_(inner), m_(m), k_(k), key_(k), r_(m), jac_(m * k) {}

    bool Get(double const *const *u, size_t row, double *residual, double **jacobians)
    {
        std::lock_guard<std::mutex> lock(mutex_);
        bool same = has_r_;
        for (size_t j = 0; same && j < k_; ++j)
            same = (key_[j] == u[j][0]);
        const bool need_jac = jacobians != nullptr;
        if (!same || (need_jac && !has_j_)) {
            has_r_ = has_j_ = false;
            std::vector<double *> cols;
            if (need_jac) {
                cols.resize(k_);
                for (size_t j = 0; j < k_; ++j)
                    cols[j] = jac_.data() + j * m_;  // block j: m x 1
            }
            if (!inner_->Evaluate(u, r_.data(), need_jac ? cols.data() : nullptr))
                return false;
            for (size_t j = 0; j < k_; ++j)
                key_[j] = u[j][0];
            has_r_ = true;
            has_j_ = need_jac;
        }
        *residual = r_[row];
        if (need_jac)
            for (size_t j = 0; j < k_; ++j)
                if (jacobians[j])
                    jacobians[j][0] = jac_[j * m_ + row];
        return true;
    }

  private:
    ceres::CostFunction *inner_;
    size_t m_, k_;
    std::mutex mutex_;
    std::vector<double> key_, r_, jac_;
    bool has_r_ = false, has_j_ = false;
};

class PointView final : public ceres::CostFunction {
  public:
    PointView(SharedEvaluation *shared, size_t row, size_t k) : shared_(shared), row_(row)
    {
        set_num_residuals(1);
        for (size_t j = 0; j < k; ++j)
            mutable_parameter_block_sizes()->push_back(1);
    }
    bool Evaluate(double const *const *u, double *residuals, double **jacobians) const override
    {
        return shared_->Get(u, row_, residuals, jacobians);
    }

  private:
    SharedEvaluation *shared_;
    size_t row_;
};

static std::unique_ptr<ceres::LossFunction> make_loss(phc_loss_kind kind, double a)
{
    switch (kind) {
    case PHC_LOSS_HUBER: return std::make_unique<ceres::HuberLoss>(a);
    case PHC_LOSS_CAUCHY: return std::make_unique<ceres::CauchyLoss>(a);
    case PHC_LOSS_SOFT_L1: return std::make_unique<ceres::SoftLOneLoss>(a);
    // Ceres's ArctanLoss(b) is b atan(s / b) with b in units of s = r^2.
    case PHC_LOSS_ARCTAN: return std::make_unique<ceres::ArctanLoss>(a * a);
    case PHC_LOSS_NONE: break;
    }
    return nullptr;
}

class AbortOnFatal final : public ceres::IterationCallback {
  public:
    explicit AbortOnFatal(const SolveState *state) : state_(state) {}
    ceres::CallbackReturnType operator()(const ceres::IterationSummary &) override
    {
        return state_->fatal.load() ? ceres::SOLVER_ABORT : ceres::SOLVER_CONTINUE;
    }

  private:
    const SolveState *state_;
};

// Reports each iteration to the caller's hook; a non-zero answer cancels.
class ReportIteration final : public ceres::IterationCallback {
  public:
    explicit ReportIteration(const phc_nls_options *o) : o_(o) {}
    ceres::CallbackReturnType operator()(const ceres::IterationSummary &it) override
    {
        if (!o_->on_iteration)
            return ceres::SOLVER_CONTINUE;
        return o_->on_iteration(it.iteration, it.cost, o_->on_iteration_data) ? ceres::SOLVER_ABORT
                                                                            : ceres::SOLVER_CONTINUE;
    }

  private:
    const phc_nls_options *o_;
};

// Everything a ceres::Problem built for one solve points into.
struct Assembly {
    std::vector<std::unique_ptr<ceres::CostFunction>> costs;
    std::vector<std::unique_ptr<ceres::LossFunction>> losses;
    std::vector<std::unique_ptr<SharedEvaluation>> shared;
};

static void quiet_glog()
{
    // Ceres logs through glog; the library must not print.  Only FATAL
    // messages (which precede an abort we prevent by validation) remain.
    static std::once_flag once;
    std::call_once(once, [] { FLAGS_minloglevel = google::GLOG_FATAL; });
}

}  // namespace

struct phc_nls {
    std::vector<Parameter> params;
    std::vector<Block> blocks;
    size_t total_residuals = 0;
};

static int internal_error(phc_error *err, const char *what)
{
    return phc_error_set(err, PHC_ERR_INTERNAL, "Ceres bridge: %s", what);
}

extern "C" phc_nls *phc_nls_new(size_t n_params)
{
    try {
        phc_nls *nls = new phc_nls;
        nls->params.resize(n_params);
        return nls;
    } catch (...) {
        return nullptr;
    }
}

extern "C" void phc_nls_free(phc_nls *nls)
{
    delete nls;
}

extern "C" int phc_nls_set_parameter(phc_nls *nls, size_t index, double lower, double upper,
                                     int fixed, double scale, phc_error *err)
{
    if (!nls)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_nls_set_parameter: NULL problem");
    if (index >= nls->params.size())
        return phc_error_set(err, PHC_ERR_INVALID, "parameter index %zu out of range (%zu parameters)",
                             index, nls->params.size());
    if (std::isnan(lower) || std::isnan(upper) || lower > upper || (!fixed && lower == upper))
        return phc_error_set(err, PHC_ERR_INVALID, "parameter %zu: bounds [%g, %g] are not an interval",
                             index, lower, upper);
    if (!(scale > 0) || !std::isfinite(scale))
        return phc_error_set(err, PHC_ERR_INVALID, "parameter %zu: scale %g must be positive and finite",
                             index, scale);
    Parameter &p = nls->params[index];
    p.lower = lower;
    p.upper = upper;
    p.fixed = fixed != 0;
    p.scale = scale;
    return PHC_OK;
}

extern "C" int phc_nls_add_block(phc_nls *nls, size_t m, const size_t *param_index, size_t k,
                                 phc_residual_fn fn, phc_derivatives derivs, phc_loss_kind loss,
                                 double loss_scale, void *user_data, phc_error *err)
{
    try {
        if (!nls || !fn || (k > 0 && !param_index))
            return phc_error_set(err, PHC_ERR_INVALID, "phc_nls_add_block: NULL argument");
        if (m == 0 || k == 0)
            return phc_error_set(err, PHC_ERR_INVALID,
                                 "a residual block needs at least one residual and one parameter (m=%zu, k=%zu)", m, k);
        if (m > static_cast<size_t>(INT32_MAX) / 2)
            return phc_error_set(err, PHC_ERR_INVALID, "too many residuals in one block (%zu)", m);
        for (size_t j = 0; j < k; ++j) {
            if (param_index[j] >= nls->params.size())
                return phc_error_set(err, PHC_ERR_INVALID, "block parameter %zu out of range (%zu parameters)",
                                     param_index[j], nls->params.size());
            for (size_t i = 0; i < j; ++i)
                if (param_index[i] == param_index[j])
                    return phc_error_set(err, PHC_ERR_INVALID, "parameter %zu appears twice in one block",
                                         param_index[j]);
        }
        if (derivs != PHC_DERIV_ANALYTIC && derivs != PHC_DERIV_CENTRAL && derivs != PHC_DERIV_RIDDERS)
            return phc_error_set(err, PHC_ERR_INVALID, "unknown derivative method %d", (int)derivs);
        if (loss < PHC_LOSS_NONE || loss > PHC_LOSS_ARCTAN)
            return phc_error_set(err, PHC_ERR_INVALID, "unknown loss %d", (int)loss);
        if (loss != PHC_LOSS_NONE && (!(loss_scale > 0) || !std::isfinite(loss_scale)))
            return phc_error_set(err, PHC_ERR_INVALID, "loss scale %g must be positive and finite", loss_scale);
        Block b;
        b.m = m;
        b.index.assign(param_index, param_index + k);
        b.fn = fn;
        b.derivs = derivs;
        b.loss = loss;
        b.loss_scale = loss_scale;
        b.user_data = user_data;
        nls->blocks.push_back(std::move(b));
        nls->total_residuals += m;
        return PHC_OK;
    } catch (const std::bad_alloc &) {
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory adding a residual block");
    } catch (...) {
        return internal_error(err, "exception in phc_nls_add_block");
    }
}

extern "C" size_t phc_nls_residual_count(const phc_nls *nls)
{
    return nls ? nls->total_residuals : 0;
}

// One residual block with exact derivatives and no loss, over parameters
// that are free, unbounded (no bound for a parameter to be held at, below)
// and in increasing order (the order Ceres would give k blocks of size 1):
// the case phc_nls_solve declares as one parameter block.
static bool one_parameter_block(const phc_nls &nls)
{
    if (nls.blocks.size() != 1)
        return false;
    const Block &b = nls.blocks[0];
    if (b.derivs != PHC_DERIV_ANALYTIC || b.loss != PHC_LOSS_NONE)
        return false;
    for (size_t j = 0; j < b.index.size(); ++j) {
        const Parameter &p = nls.params[b.index[j]];
        if (p.fixed || std::isfinite(p.lower) || std::isfinite(p.upper) || (j > 0 && b.index[j] <= b.index[j - 1]))
            return false;
    }
    return true;
}

static int check_point(const phc_nls *nls, const double *x, phc_error *err)
{
    for (size_t i = 0; i < nls->params.size(); ++i) {
        const Parameter &p = nls->params[i];
        if (!std::isfinite(x[i]))
            return phc_error_set(err, PHC_ERR_INVALID, "parameter %zu: value %g is not finite", i, x[i]);
        if (!p.fixed && (x[i] < p.lower || x[i] > p.upper))
            return phc_error_set(err, PHC_ERR_INVALID, "parameter %zu: value %.17g outside its bounds [%g, %g]",
                                 i, x[i], p.lower, p.upper);
    }
    return PHC_OK;
}

extern "C" int phc_nls_solve(phc_nls *nls, const phc_nls_options *options, double *x,
                             phc_nls_summary *summary, phc_error *err)
{
    try {
        if (!nls || !options || !x || !summary)
            return phc_error_set(err, PHC_ERR_INVALID, "phc_nls_solve: NULL argument");
        if (nls->blocks.empty())
            return phc_error_set(err, PHC_ERR_INVALID, "the problem has no residual blocks");
        if (options->max_iterations < 1 || options->num_threads < 1)
            return phc_error_set(err, PHC_ERR_INVALID, "max_iterations and num_threads must be at least 1");
        int rc = check_point(nls, x, err);
        if (rc)
            return rc;
        quiet_glog();

        const size_t n = nls->params.size();
        std::vector<bool> used(n, false);
        for (const Block &b : nls->blocks)
            for (size_t i : b.index)
                used[i] = true;

        std::vector<double> u(n);
        for (size_t i = 0; i < n; ++i)
            u[i] = x[i] / nls->params[i].scale;

        SolveState state;
        Assembly assembly;
        ceres::Problem::Options popts;
        popts.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
        popts.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
        ceres::Problem problem(popts);
        // One data set with exact derivatives over free, unbounded
        // parameters: its parameters are one Ceres parameter block (ub), in
        // the order the blocks of size 1 would have (one_parameter_block),
        // so Ceres assembles the same Jacobian and gradient with a
        // fraction of its per-block bookkeeping.
        const bool one = one_parameter_block(*nls);
        std::vector<double> ub;
        if (one) {
            const Block &b = nls->blocks[0];
            for (size_t i : b.index)
                ub.push_back(u[i]);
            problem.AddParameterBlock(ub.data(), static_cast<int>(ub.size()));
            assembly.costs.push_back(std::make_unique<AnalyticCost>(b, nls->params, &state, true));
            problem.AddResidualBlock(assembly.costs.back().get(), nullptr, ub.data());
        }
        for (size_t i = 0; i < n && !one; ++i) {
            if (!used[i])
                continue;
            const Parameter &p = nls->params[i];
            problem.AddParameterBlock(&u[i], 1);
            if (p.fixed) {
                problem.SetParameterBlockConstant(&u[i]);
                continue;
            }
            if (std::isfinite(p.lower))
                problem.SetParameterLowerBound(&u[i], 0, p.lower / p.scale);
            if (std::isfinite(p.upper))
                problem.SetParameterUpperBound(&u[i], 0, p.upper / p.scale);
        }
        for (const Block &b : nls->blocks) {
            if (one)
                break;
            std::vector<double *> blocks;
            for (size_t i : b.index)
                blocks.push_back(&u[i]);
            assembly.costs.push_back(make_block_cost(b, nls->params, &state));
            ceres::CostFunction *whole = assembly.costs.back().get();
            if (b.loss == PHC_LOSS_NONE) {
                problem.AddResidualBlock(whole, nullptr, blocks);
                continue;
            }
            assembly.losses.push_back(make_loss(b.loss, b.loss_scale));
            ceres::LossFunction *loss = assembly.losses.back().get();
            assembly.shared.push_back(std::make_unique<SharedEvaluation>(whole, b.m, b.index.size()));
            SharedEvaluation *shared = assembly.shared.back().get();
            for (size_t row = 0; row < b.m; ++row) {
                assembly.costs.push_back(std::make_unique<PointView>(shared, row, b.index.size()));
                problem.AddResidualBlock(assembly.costs.back().get(), loss, blocks);
            }
        }

        ceres::Solver::Options o;
        o.minimizer_type = ceres::TRUST_REGION;
        o.trust_region_strategy_type =
            options->method == PHC_DOGLEG ? ceres::DOGLEG : ceres::LEVENBERG_MARQUARDT;
        o.linear_solver_type = ceres::DENSE_QR;
        o.max_num_iterations = options->max_iterations;
        o.function_tolerance = options->function_tolerance;
        o.gradient_tolerance = options->gradient_tolerance;
        o.parameter_tolerance = options->parameter_tolerance;
        o.num_threads = options->num_threads;
        o.logging_type = ceres::SILENT;
        o.minimizer_progress_to_stdout = false;
        AbortOnFatal abort_cb(&state);
        o.callbacks.push_back(&abort_cb);
        ReportIteration report_cb(options);
        if (options->on_iteration)
            o.callbacks.push_back(&report_cb);

        ceres::Solver::Summary s;
        ceres::Solve(o, &problem, &s);
        for (size_t j = 0; j < ub.size(); ++j)
            u[nls->blocks[0].index[j]] = ub[j];

        // Ceres projects each trust-region step onto the bounds (Ceres issue
        // #187): once a parameter reaches its bound, the steps that would
        // also bring the others to their conditional optimum point outside
        // the box, are cut, and the solve stops short (y = a + b x with
        // b >= 0 on falling data: a ended 35% off).  Hold the parameters
        // that ended on a bound there and solve again; then release them and
        // solve once more so that one can leave its bound.
        for (int round = 0; round < 4 && s.IsSolutionUsable() && !state.fatal.load(); ++round) {
            std::vector<size_t> pinned;
            for (size_t i = 0; i < n; ++i) {
                const Parameter &p = nls->params[i];
                if (used[i] && !p.fixed && (u[i] == p.lower / p.scale || u[i] == p.upper / p.scale))
                    pinned.push_back(i);
            }
            if (pinned.empty())
                break;
            const std::vector<double> keep(u);
            ceres::Solver::Summary held, released;
            for (size_t i : pinned)
                problem.SetParameterBlockConstant(&u[i]);
            ceres::Solve(o, &problem, &held);
            for (size_t i : pinned)
                problem.SetParameterBlockVariable(&u[i]);
            if (!held.IsSolutionUsable() || !(held.final_cost < s.final_cost)) {
                std::copy(keep.begin(), keep.end(), u.begin());
                break;  // already optimal given the bound (or a failure)
            }
            const std::vector<double> held_u(u);
            ceres::Solve(o, &problem, &released);
            const bool use_released = released.IsSolutionUsable() && released.final_cost <= held.final_cost;
            if (!use_released)
                std::copy(held_u.begin(), held_u.end(), u.begin());
            const ceres::Solver::Summary &last = use_released ? released : held;
            for (const ceres::Solver::Summary *extra : {&held, &released}) {
                s.num_successful_steps += extra->num_successful_steps;
                s.num_unsuccessful_steps += extra->num_unsuccessful_steps;
                s.num_residual_evaluations += extra->num_residual_evaluations;
                s.num_jacobian_evaluations += extra->num_jacobian_evaluations;
                s.total_time_in_seconds += extra->total_time_in_seconds;
            }
            s.final_cost = last.final_cost;
            s.termination_type = last.termination_type;
            s.message = last.message;
        }

        std::memset(summary, 0, sizeof *summary);
        std::snprintf(summary->termination, sizeof summary->termination, "%s", s.message.c_str());
        summary->iterations = s.num_successful_steps + s.num_unsuccessful_steps;
        summary->initial_cost = s.initial_cost;
        summary->final_cost = s.final_cost;
        summary->residual_evaluations = s.num_residual_evaluations;
        summary->jacobian_evaluations = s.num_jacobian_evaluations;
        summary->wall_time = s.total_time_in_seconds;
        switch (s.termination_type) {
        case ceres::CONVERGENCE:
        case ceres::USER_SUCCESS: summary->outcome = PHC_NLS_CONVERGED; break;
        case ceres::NO_CONVERGENCE: summary->outcome = PHC_NLS_NOT_CONVERGED; break;
        default: summary->outcome = PHC_NLS_FAILED; break;
        }
        if (state.fatal.load())
            return phc_error_set(err, PHC_ERR_NUMERIC,
                                 "a residual callback failed fatally (code %d); the solve was stopped",
                                 state.fatal_code.load());
        if (!s.IsSolutionUsable()) {
            summary->outcome = PHC_NLS_FAILED;
            return PHC_OK;  // x keeps the start
        }
        for (size_t i = 0; i < n; ++i)
            if (used[i] && !nls->params[i].fixed)
                x[i] = u[i] * nls->params[i].scale;
        return PHC_OK;
    } catch (const std::bad_alloc &) {
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory in the solver");
    } catch (const std::exception &e) {
        return internal_error(err, e.what());
    } catch (...) {
        return internal_error(err, "unknown exception in phc_nls_solve");
    }
}

extern "C" int phc_nls_evaluate(phc_nls *nls, const double *x, double *residuals, double *jacobian,
                                double *cost, phc_error *err)
{
    try {
        if (!nls || !x)
            return phc_error_set(err, PHC_ERR_INVALID, "phc_nls_evaluate: NULL argument");
        for (size_t i = 0; i < nls->params.size(); ++i)
            if (!std::isfinite(x[i]))
                return phc_error_set(err, PHC_ERR_INVALID, "parameter %zu: value %g is not finite", i, x[i]);
        const size_t n = nls->params.size();
        if (jacobian)
            std::fill(jacobian, jacobian + nls->total_residuals * n, 0.0);
        double total_cost = 0.0;
        size_t row0 = 0;
        for (const Block &b : nls->blocks) {
            const size_t k = b.index.size();
            std::vector<double> xb(k), r(b.m), jac(jacobian ? b.m * k : 0);
            for (size_t j = 0; j < k; ++j)
                xb[j] = x[b.index[j]];
            // Analytic blocks give the residuals and the Jacobian in one call, as
            // Ceres asks for them while solving (one model run instead of two: a
            // water fit's analysis and polish evaluate each point once).
            const bool one_call = jacobian && b.derivs == PHC_DERIV_ANALYTIC;
            if (one_call ? !call_block(b, xb.data(), r.data(), jac.data(), nullptr)
                         : !call_block(b, xb.data(), r.data(), nullptr, nullptr)) {
                if (!one_call || !call_block(b, xb.data(), r.data(), nullptr, nullptr))
                    return phc_error_set(err, PHC_ERR_DOMAIN,
                                         "residual block %zu cannot be evaluated at these parameters",
                                         static_cast<size_t>(&b - nls->blocks.data()));
                return phc_error_set(err, PHC_ERR_DOMAIN, "Jacobian of block %zu cannot be evaluated",
                                     static_cast<size_t>(&b - nls->blocks.data()));
            }
            if (jacobian) {
                if (one_call) {
                    // filled above
                } else {
                    std::unique_ptr<ceres::CostFunction> c = make_block_cost(b, nls->params, nullptr);
                    std::vector<double> u(k), r2(b.m), cols(b.m * k);
                    std::vector<const double *> up(k);
                    std::vector<double *> jp(k);
                    for (size_t j = 0; j < k; ++j) {
                        u[j] = xb[j] / nls->params[b.index[j]].scale;
                        up[j] = &u[j];
                        jp[j] = cols.data() + j * b.m;
                    }
                    if (!c->Evaluate(up.data(), r2.data(), jp.data()))
                        return phc_error_set(err, PHC_ERR_DOMAIN,
                                             "numerical Jacobian of block %zu cannot be evaluated",
                                             static_cast<size_t>(&b - nls->blocks.data()));
                    for (size_t j = 0; j < k; ++j)
                        for (size_t i = 0; i < b.m; ++i)
                            jac[i * k + j] = cols[j * b.m + i] / nls->params[b.index[j]].scale;
                }
                for (size_t i = 0; i < b.m; ++i)
                    for (size_t j = 0; j < k; ++j)
                        jacobian[(row0 + i) * n + b.index[j]] = jac[i * k + j];
            }
            std::unique_ptr<ceres::LossFunction> loss = make_loss(b.loss, b.loss_scale);
            for (size_t i = 0; i < b.m; ++i) {
                const double s = r[i] * r[i];
                double rho[3] = {s, 1.0, 0.0};
                if (loss)
                    loss->Evaluate(s, rho);
                total_cost += 0.5 * rho[0];
                if (residuals)
                    residuals[row0 + i] = r[i];
            }
            row0 += b.m;
        }
        if (cost)
            *cost = total_cost;
        return PHC_OK;
    } catch (const std::bad_alloc &) {
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory evaluating the problem");
    } catch (const std::exception &e) {
        return internal_error(err, e.what());
    } catch (...) {
        return internal_error(err, "unknown exception in phc_nls_evaluate");
    }
}

/* The module's entry point (fit/engine/ceres_module_internal.h): this file
 * is compiled into phytocal_ceres.so, which libphytocal opens on the first
 * phc_nls_new. */
static const phc_ceres_module_table phc_ceres_module = {
    phc_nls_new,   phc_nls_free,  phc_nls_set_parameter, phc_nls_add_block, phc_nls_residual_count,
    phc_nls_solve, phc_nls_evaluate};

extern "C" const void *phc_ceres_module_entry(int abi)
{
    return abi == PHC_CERES_MODULE_ABI ? &phc_ceres_module : nullptr;
}
