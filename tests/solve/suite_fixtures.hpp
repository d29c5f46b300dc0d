#pragma once
// Shared by the solver-suite tests: objectives with known minima, small sheared networks, and wrappers that
// break an objective on purpose.
#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "fibernet/box/box.hpp"
#include "fibernet/energy/network_energy.hpp"
#include "fibernet/energy/objective.hpp"
#include "fibernet/model/discretize.hpp"
#include "fibernet/network/mikado.hpp"

namespace suite_test {

using fibernet::Objective;

// Extended Rosenbrock, f = sum_i 100 (x_{2i+1} - x_{2i}^2)^2 + (1 - x_{2i})^2: minimum 0 at all ones, a curved
// valley, an indefinite Hessian away from it. Each pair is one "element" (per-element PSD projection).
// `free` more unknowns that f does not depend on (a zero mode, like a translation of a periodic network).
class Rosenbrock : public Objective {
public:
    explicit Rosenbrock(int pairs, int free = 0) : m_(2 * pairs), n_(2 * pairs + free), P_(n_, n_) {
        std::vector<Eigen::Triplet<double>> t;
        for (int i = 0; i < m_; i += 2) t.emplace_back(i, i, 0.0), t.emplace_back(i, i + 1, 0.0), t.emplace_back(i + 1, i + 1, 0.0);
        for (int i = m_; i < n_; ++i) t.emplace_back(i, i, 0.0);
        P_.setFromTriplets(t.begin(), t.end());
        P_.makeCompressed();
    }
    int size() const override { return n_; }
    double value(const Eigen::VectorXd& x) override {
        double f = 0;
        for (int i = 0; i < m_; i += 2) f += 100 * std::pow(x[i + 1] - x[i] * x[i], 2) + std::pow(1 - x[i], 2);
        return f;
    }
    double gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) override {
        g.setZero(n_);
        for (int i = 0; i < m_; i += 2) {
            const double r = x[i + 1] - x[i] * x[i];
            g[i] = -400 * r * x[i] - 2 * (1 - x[i]);
            g[i + 1] = 200 * r;
        }
        return value(x);
    }
    double hessian(const Eigen::VectorXd& x, Eigen::VectorXd& g, Eigen::SparseMatrix<double>& H, bool psd) override {
        const double f = gradient(x, g);
        H = P_;
        for (int i = 0; i < m_; i += 2) {
            Eigen::Matrix2d h;
            h(0, 0) = 1200 * x[i] * x[i] - 400 * x[i + 1] + 2;
            h(0, 1) = h(1, 0) = -400 * x[i];
            h(1, 1) = 200;
            if (psd) {
                Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(h);
                h = es.eigenvectors() * es.eigenvalues().cwiseMax(0.0).asDiagonal() * es.eigenvectors().transpose();
            }
            H.coeffRef(i, i) = h(0, 0), H.coeffRef(i, i + 1) = h(0, 1), H.coeffRef(i + 1, i + 1) = h(1, 1);
        }
        return f;
    }
    const Eigen::SparseMatrix<double>& hessian_pattern() const override { return P_; }

private:
    int m_, n_;
    Eigen::SparseMatrix<double> P_;
};

// A gradient that does not belong to the energy: g[k] += c. Where the energy does not change along some
// direction u containing coordinate k, the reported gradient never vanishes, so no solver may report convergence:
// for a periodic network (translations: the x coordinates sum to zero in the true gradient) max|g| >= |c| / nodes;
// for Rosenbrock(pairs, 1) and k the free unknown, max|g| >= |c|.
class WrongGradient : public Objective {
public:
    WrongGradient(Objective& f, double c, int k = 0) : f_(f), c_(c), k_(k) {}
    int size() const override { return f_.size(); }
    double value(const Eigen::VectorXd& q) override { return f_.value(q); }
    double gradient(const Eigen::VectorXd& q, Eigen::VectorXd& g) override {
        const double e = f_.gradient(q, g);
        g[k_] += c_;
        return e;
    }
    double hessian(const Eigen::VectorXd& q, Eigen::VectorXd& g, Eigen::SparseMatrix<double>& H, bool psd) override {
        const double e = f_.hessian(q, g, H, psd);
        g[k_] += c_;
        return e;
    }
    const Eigen::SparseMatrix<double>& hessian_pattern() const override { return f_.hessian_pattern(); }

private:
    Objective& f_;
    double c_;
    int k_;
};

// A small periodic Mikado network under simple shear, with its energy and affine start.
struct ShearedNetwork {
    fibernet::Model model;
    std::unique_ptr<fibernet::NetworkEnergy> energy;
    std::unique_ptr<fibernet::StrainedEnergy> objective;
    Eigen::VectorXd q0;

    ShearedNetwork(double L, double q, fibernet::Scheme scheme, double a, double gamma, std::uint64_t seed = 1) {
        fibernet::MikadoParams mp;
        mp.L = L, mp.q = q, mp.pl = 1, mp.seed = seed, mp.periodic = true;
        fibernet::DiscretizationParams dp;
        dp.scheme = scheme, dp.aspect_ratio = a;
        model = fibernet::discretize(fibernet::generate_mikado(mp), dp);
        energy = std::make_unique<fibernet::NetworkEnergy>(model);
        const Eigen::Matrix2d F = fibernet::deformation(fibernet::StrainKind::Shear, gamma);
        objective = std::make_unique<fibernet::StrainedEnergy>(*energy, F);
        q0 = energy->affine_map(energy->dofs(model.x), Eigen::Matrix2d::Identity(), F);
    }
};

}  // namespace suite_test
