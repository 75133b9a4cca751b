#ifndef CABLESIM_ENGINE_LINEAR_KRYLOV_H_
#define CABLESIM_ENGINE_LINEAR_KRYLOV_H_

// Preconditioned Krylov solvers with all work vectors allocated up front, so
// that a solve inside the stepping loop allocates nothing.
//
// Why not Eigen's unsupported IterativeSolvers: its minres() and gmres()
// construct their work vectors on every call (measured: one heap allocation
// per vector per solve). tests/krylov_test.cc checks these against Eigen's
// MINRES and a dense LU on random systems.
//
// Operators are callables `op(const VectorXd& x, VectorXd& y)` computing
// y = A x, and preconditioners `prec(const VectorXd& r, VectorXd& z)`
// computing z = P^{-1} r.

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Core>

namespace cablesim {

struct KrylovResult {
  int iterations = 0;
  // The solver's own estimate of the relative residual: in the P^{-1} norm
  // for MINRES, the Euclidean norm for GMRES. Callers check the true one.
  double estimated_relative_residual = 0;
  bool converged = false;
};

// MINRES (Paige and Saunders, 1975) for a symmetric, possibly indefinite A
// with a symmetric positive definite preconditioner P. Starts from x = 0.
class Minres {
 public:
  void Resize(int n) {
    if (r1_.size() == n) return;
    for (Eigen::VectorXd* v : {&r1_, &r2_, &y_, &v_, &w_, &w1_, &w2_}) v->resize(n);
  }

  template <typename Op, typename Prec>
  KrylovResult Solve(const Op& op, const Prec& prec, const Eigen::VectorXd& b, double rel_tol,
                     int max_iterations, Eigen::VectorXd& x) {
    Resize(static_cast<int>(b.size()));
    KrylovResult result;
    x.setZero();
    r1_ = b;
    prec(r1_, y_);
    double beta1 = r1_.dot(y_);
    if (!(beta1 > 0)) {  // b = 0 (or P not positive definite)
      result.converged = beta1 == 0;
      return result;
    }
    beta1 = std::sqrt(beta1);
    double oldb = 0, beta = beta1, dbar = 0, epsln = 0, phibar = beta1;
    double cs = -1, sn = 0;
    r2_ = r1_;
    w_.setZero();
    w2_.setZero();
    for (int itn = 1; itn <= max_iterations; ++itn) {
      v_ = y_ / beta;
      op(v_, y_);
      if (itn >= 2) y_ -= (beta / oldb) * r1_;
      const double alfa = v_.dot(y_);
      y_ -= (alfa / beta) * r2_;
      r1_.swap(r2_);
      r2_ = y_;
      prec(r2_, y_);
      oldb = beta;
      const double beta2 = r2_.dot(y_);
      beta = std::sqrt(std::max(beta2, 0.0));
      const double oldeps = epsln;
      const double delta = cs * dbar + sn * alfa;
      const double gbar = sn * dbar - cs * alfa;
      epsln = sn * beta;
      dbar = -cs * beta;
      const double gamma =
          std::max(std::hypot(gbar, beta), std::numeric_limits<double>::min());
      cs = gbar / gamma;
      sn = beta / gamma;
      const double phi = cs * phibar;
      phibar *= sn;
      w1_.swap(w2_);
      w2_.swap(w_);
      w_ = (v_ - oldeps * w1_ - delta * w2_) / gamma;
      x += phi * w_;
      result.iterations = itn;
      result.estimated_relative_residual = phibar / beta1;
      if (result.estimated_relative_residual <= rel_tol || beta == 0) {
        result.converged = true;
        break;
      }
      if (!std::isfinite(phibar)) break;
    }
    return result;
  }

 private:
  Eigen::VectorXd r1_, r2_, y_, v_, w_, w1_, w2_;
};

// Restarted GMRES(m) with right preconditioning (Saad and Schultz, 1986):
// minimizes the true residual |b - A x| over x = P^{-1} V y.
class Gmres {
 public:
  explicit Gmres(int restart = 40) : m_(restart) {}

  void Resize(int n) {
    if (v_.rows() == n) return;
    v_.resize(n, m_ + 1);
    h_.resize(m_ + 1, m_);
    cs_.resize(m_);
    sn_.resize(m_);
    g_.resize(m_ + 1);
    y_.resize(m_);
    r_.resize(n);
    z_.resize(n);
    t_.resize(n);
  }

  template <typename Op, typename Prec>
  KrylovResult Solve(const Op& op, const Prec& prec, const Eigen::VectorXd& b, double rel_tol,
                     int max_iterations, Eigen::VectorXd& x) {
    Resize(static_cast<int>(b.size()));
    KrylovResult result;
    x.setZero();
    const double bnorm = b.norm();
    if (bnorm == 0) {
      result.converged = true;
      return result;
    }
    int total = 0;
    r_ = b;
    while (total < max_iterations) {
      double beta = r_.norm();
      result.estimated_relative_residual = beta / bnorm;
      if (beta <= rel_tol * bnorm) {
        result.converged = true;
        break;
      }
      v_.col(0) = r_ / beta;
      g_.setZero();
      g_(0) = beta;
      int k = 0;
      for (; k < m_ && total < max_iterations; ++k) {
        t_ = v_.col(k);
        prec(t_, z_);
        op(z_, t_);
        for (int i = 0; i <= k; ++i) {  // modified Gram-Schmidt
          h_(i, k) = t_.dot(v_.col(i));
          t_ -= h_(i, k) * v_.col(i);
        }
        h_(k + 1, k) = t_.norm();
        if (h_(k + 1, k) > 0) v_.col(k + 1) = t_ / h_(k + 1, k);
        for (int i = 0; i < k; ++i) {  // apply the earlier rotations
          const double a = h_(i, k), c = h_(i + 1, k);
          h_(i, k) = cs_(i) * a + sn_(i) * c;
          h_(i + 1, k) = -sn_(i) * a + cs_(i) * c;
        }
        const double a = h_(k, k), c = h_(k + 1, k);
        const double rr = std::max(std::hypot(a, c), std::numeric_limits<double>::min());
        cs_(k) = a / rr;
        sn_(k) = c / rr;
        h_(k, k) = rr;
        h_(k + 1, k) = 0;
        g_(k + 1) = -sn_(k) * g_(k);
        g_(k) *= cs_(k);
        ++total;
        result.estimated_relative_residual = std::abs(g_(k + 1)) / bnorm;
        if (result.estimated_relative_residual <= rel_tol) {
          ++k;
          break;
        }
      }
      // y = H^{-1} g on the leading k x k triangle; x += P^{-1} V y.
      for (int i = k - 1; i >= 0; --i) {
        double acc = g_(i);
        for (int j = i + 1; j < k; ++j) acc -= h_(i, j) * y_(j);
        y_(i) = acc / h_(i, i);
      }
      t_.setZero();
      for (int j = 0; j < k; ++j) t_ += y_(j) * v_.col(j);
      prec(t_, z_);
      x += z_;
      // True residual for the restart (and the final answer).
      op(x, t_);
      r_ = b - t_;
      if (!std::isfinite(r_.squaredNorm())) break;
    }
    result.iterations = total;
    result.estimated_relative_residual = r_.norm() / bnorm;
    result.converged = result.estimated_relative_residual <= rel_tol * 10;
    return result;
  }

 private:
  int m_;
  Eigen::MatrixXd v_, h_;
  Eigen::VectorXd cs_, sn_, g_, y_, r_, z_, t_;
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_LINEAR_KRYLOV_H_
