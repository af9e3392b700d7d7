// SPDX-License-Identifier: Apache-2.0
#include "deform/swept_fluid.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Geometry>

#include "core/format.h"
#include "core/monotone_cubic.h"
#include "deform/box_solve.h"
#include "deform/flow.h"
#include "deform/step_chain.h"

namespace sweepers {

namespace {

// The MAC grid: n^3 cells; component a of sample (i, j, k) is the velocity through the face
// of cell (i, j, k) below it along a, at grid coordinates (i, j, k) + 1/2 except along a.
// Samples run to n on every axis; those that are not faces of the grid stay zero.
class Mac {
  public:
    explicit Mac(int n)
        : n_(n), v_(std::size_t(n + 1) * (n + 1) * (n + 1), Eigen::Vector3d::Zero()) {}
    int n() const { return n_; }
    std::size_t index(int i, int j, int k) const {
        return std::size_t(i) +
               std::size_t(n_ + 1) * (std::size_t(j) + std::size_t(n_ + 1) * std::size_t(k));
    }
    // Whether (i, j, k) holds a face of component a inside the cube (walls excluded).
    bool inner(int a, int i, int j, int k) const {
        const int c[3] = {i, j, k};
        for (int b = 0; b < 3; ++b)
            if (b == a ? (c[b] < 1 || c[b] > n_ - 1) : (c[b] < 0 || c[b] > n_ - 1)) return false;
        return true;
    }
    double get(int a, int i, int j, int k) const {
        if (i < 0 || j < 0 || k < 0 || i > n_ || j > n_ || k > n_) return 0.0;
        return v_[index(i, j, k)][a];
    }
    double& at(int a, int i, int j, int k) { return v_[index(i, j, k)][a]; }
    // Grid coordinates of face (i, j, k) of component a.
    static Eigen::Vector3d position(int a, int i, int j, int k) {
        Eigen::Vector3d p(i + 0.5, j + 0.5, k + 0.5);
        p[a] -= 0.5;
        return p;
    }
    // Component a at grid coordinates g: trilinear (for tracing), or the monotone cubic.
    double sample(int a, const Eigen::Vector3d& g, bool cubic) const {
        Eigen::Vector3d u = g - Eigen::Vector3d::Constant(0.5);
        u[a] += 0.5;
        const Eigen::Vector3d f = u.array().floor();
        const int i = int(f[0]), j = int(f[1]), k = int(f[2]);
        const Eigen::Vector3d t = u - f;
        if (!cubic) {
            double s = 0.0;
            for (int z = 0; z < 2; ++z)
                for (int y = 0; y < 2; ++y)
                    for (int x = 0; x < 2; ++x)
                        s += (x ? t[0] : 1 - t[0]) * (y ? t[1] : 1 - t[1]) * (z ? t[2] : 1 - t[2]) *
                             get(a, i + x, j + y, k + z);
            return s;
        }
        double plane[4];
        for (int z = 0; z < 4; ++z) {
            double row[4];
            for (int y = 0; y < 4; ++y)
                row[y] = monotoneCubic(
                    get(a, i - 1, j + y - 1, k + z - 1), get(a, i, j + y - 1, k + z - 1),
                    get(a, i + 1, j + y - 1, k + z - 1), get(a, i + 2, j + y - 1, k + z - 1), t[0]);
            plane[z] = monotoneCubic(row[0], row[1], row[2], row[3], t[1]);
        }
        return monotoneCubic(plane[0], plane[1], plane[2], plane[3], t[2]);
    }
    Eigen::Vector3d velocity(const Eigen::Vector3d& g) const {
        return {sample(0, g, false), sample(1, g, false), sample(2, g, false)};
    }
    // The divergence of cell (i, j, k): what flows out through its six faces.
    double divergence(int i, int j, int k) const {
        return get(0, i + 1, j, k) - get(0, i, j, k) + get(1, i, j + 1, k) - get(1, i, j, k) +
               get(2, i, j, k + 1) - get(2, i, j, k);
    }
    const std::vector<Eigen::Vector3d>& values() const { return v_; }

  private:
    int n_;
    std::vector<Eigen::Vector3d> v_;
};

// Implicit diffusion of component a (4.23): (1 - dt nu Laplacian) u2 = u1 on the inner
// faces; faces on or beyond the walls are zero. The inner faces of component a run from 1 to
// n - 1 along a (the walls at 0 and n hold zero) and from 0 to n - 1 across (zero beyond).
void diffuse(Mac& u, int a, double dtNu) {
    const int n = u.n();
    BoxProblem box;
    box.dims = {n, n, n};
    box.dims[a] = n - 1;
    box.ends = {BoxEnds::Zero, BoxEnds::Zero, BoxEnds::Zero};
    box.shift = 1.0;
    box.scale = dtNu;
    // The box's cells in order (x fastest), as the faces they are.
    const int lo[3] = {a == 0, a == 1, a == 2};
    const auto eachFace = [&](const auto& visit) {
        std::size_t f = 0;
        for (int k = 0; k < box.dims[2]; ++k)
            for (int j = 0; j < box.dims[1]; ++j)
                for (int i = 0; i < box.dims[0]; ++i)
                    visit(f++, i + lo[0], j + lo[1], k + lo[2]);
    };
    std::vector<double> x(box.size());
    eachFace([&](std::size_t f, int i, int j, int k) { x[f] = u.get(a, i, j, k); });
    solveBox(box, x);
    eachFace([&](std::size_t f, int i, int j, int k) { u.at(a, i, j, k) = x[f]; });
}

// The projection (4.24, 4.25): -Laplacian p = -div u2 / dt on the cells, no flow through the
// walls (Neumann), then u3 = u2 - dt grad p on the inner faces. The Neumann problem fixes p
// up to a constant (the solve takes the one of zero mean); its right-hand side sums to zero
// since nothing crosses the walls.
void project(Mac& u, double dt) {
    const int n = u.n();
    auto cell = [n](int i, int j, int k) { return i + n * (j + n * k); };
    std::vector<double> p(std::size_t(n) * n * n);
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i)
                p[cell(i, j, k)] = -u.divergence(i, j, k) / dt;
    BoxProblem box;
    box.dims = {n, n, n};
    box.ends = {BoxEnds::Closed, BoxEnds::Closed, BoxEnds::Closed};
    solveBox(box, p);
    for (int a = 0; a < 3; ++a)
        for (int k = 0; k < n; ++k)
            for (int j = 0; j < n; ++j)
                for (int i = 0; i < n; ++i) {
                    if (!u.inner(a, i, j, k)) continue;
                    int o[3] = {i, j, k};
                    --o[a];
                    u.at(a, i, j, k) -= dt * (p[cell(i, j, k)] - p[cell(o[0], o[1], o[2])]);
                }
}

} // namespace

FluidSolution solveSweptFluid(const FluidSpec& spec) {
    const int n = spec.cells;
    if (n < 8 || n > 512) throw std::invalid_argument("the fluid grid needs 8 to 512 cells a side");
    if (!(spec.ballRadius > 0.0) || !(spec.ballRadius <= n / 4.0))
        throw std::invalid_argument("the fluid's ball must fit in the middle half of its grid");
    if (!(spec.viscosity >= 0.0) || !(spec.timeStep > 0.0))
        throw std::invalid_argument("the fluid needs a viscosity and a time step");
    const double dt = spec.timeStep;
    const Eigen::Vector3d centre = Eigen::Vector3d::Constant(0.5 * n);
    // v0: the faces inside the ball move with the tool, v_INIT = (1, 0, 0).
    Mac v0(n);
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 1; i < n; ++i)
                if ((Mac::position(0, i, j, k) - centre).norm() <= spec.ballRadius)
                    v0.at(0, i, j, k) = 1.0;
    // Convection by the method of characteristics: each face takes the value found where its
    // characteristic was dt earlier (the monotone cubic keeps it within the data). Only near
    // the ball: farther than its radius, the trace (dt at speed 1) and the cubic's reach (2
    // faces) and a face for the trilinear trace, every value read is zero.
    const double reach = spec.ballRadius + dt + 4.0;
    Mac u(n);
    for (int a = 0; a < 3; ++a)
        for (int k = 0; k <= n; ++k)
            for (int j = 0; j <= n; ++j)
                for (int i = 0; i <= n; ++i) {
                    if (!v0.inner(a, i, j, k)) continue;
                    const Eigen::Vector3d g = Mac::position(a, i, j, k);
                    if ((g - centre).cwiseAbs().maxCoeff() > reach) continue;
                    u.at(a, i, j, k) = v0.sample(a, g - dt * v0.velocity(g), true);
                }
    for (int a = 0; a < 3; ++a)
        diffuse(u, a, dt * spec.viscosity);
    project(u, dt);
    FluidSolution out;
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i)
                out.divergence = std::max(out.divergence, std::abs(u.divergence(i, j, k)));
    VelocitySamples& s = out.samples;
    s.dims = {n + 1, n + 1, n + 1};
    s.origin = Eigen::Vector3d::Constant(0.5 - 0.5 * n);
    s.spacing = 1.0;
    s.staggered = true;
    s.values.reserve(u.values().size());
    for (const Eigen::Vector3d& v : u.values())
        s.values.push_back(v.cast<float>());
    return out;
}

SweptFluid::SweptFluid(const VelocitySamples& solution, double ballRadiusCells)
    : field(std::make_shared<SampledField>(solution)), ballRadius(ballRadiusCells),
      centerSpeed(field->at(Eigen::Vector3d::Zero()).norm()) {
    if (!(ballRadius > 0.0) || !(centerSpeed > 0.0))
        throw std::invalid_argument("the fluid does not move at the tool's centre");
}

namespace {

// A field moved by a similarity: the local field turned by `turn`, scaled by `scale` and
// centred at `centre`. Its Jacobian is the local one conjugated by the turn, so the local
// Lipschitz bound holds.
class PlacedField : public VelocityField {
  public:
    PlacedField(std::shared_ptr<const VelocityField> local, const Eigen::Vector3d& centre,
                const Eigen::Matrix3d& turn, double scale)
        : local_(std::move(local)), c_(centre), r_(turn), h_(scale) {
        for (const Eigen::Vector3d& corner : local_->support().corners())
            support_.add(c_ + h_ * (r_ * corner));
    }
    Eigen::Vector3d at(const Eigen::Vector3d& p, double t) const override {
        return h_ * (r_ * local_->at(r_.transpose() * (p - c_) / h_, t));
    }
    double lipschitz() const override { return local_->lipschitz(); }
    Box support() const override { return support_; }

  private:
    std::shared_ptr<const VelocityField> local_;
    Eigen::Vector3d c_;
    Eigen::Matrix3d r_;
    double h_;
    Box support_;
};

} // namespace

int sweptFluidSteps(const SweptFluid& fluid, double radius, const Eigen::Vector3d& from,
                    const Eigen::Vector3d& to) {
    if (!(radius > 0.0) || !std::isfinite(radius))
        throw std::invalid_argument("a fluid tool needs a positive radius");
    const double local = (to - from).norm() * fluid.ballRadius / radius; // |W^-1 t|
    if (!(local > 0.0) || !std::isfinite(local))
        throw std::invalid_argument("a fluid tool's move needs a length");
    const double steps = std::max(1.0, std::ceil(local / fluid.centerSpeed)); // 4.26
    // (Compared as a double: a move far longer than the ball counts past any int.)
    if (!(steps <= kMostFluidSteps))
        throw std::invalid_argument("a fluid tool moving " + formatNumber((to - from).norm()) +
                                    " at radius " + formatNumber(radius) + " takes " +
                                    formatNumber(steps) +
                                    " flow steps; at most 1e6 (a larger ball, or a shorter path)");
    return int(steps);
}

std::unique_ptr<StepDeformation> sweptFluidSegment(const SweptFluid& fluid, double radius,
                                                   const Eigen::Vector3d& from,
                                                   const Eigen::Vector3d& to) {
    const int s = sweptFluidSteps(fluid, radius, from, to);
    const Eigen::Vector3d t = to - from;
    const double h = radius / fluid.ballRadius;              // world units per cell
    const double l = t.norm() / h / (s * fluid.centerSpeed); // 4.27
    const Eigen::Matrix3d turn =
        Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitX(), t).toRotationMatrix();
    std::vector<std::unique_ptr<StepDeformation>> steps;
    for (int k = 0; k < s; ++k) {
        const Eigen::Vector3d centre = from + (k + 0.5) / s * t;
        steps.push_back(std::make_unique<FlowStep>(
            std::make_shared<PlacedField>(fluid.field, centre, turn, h), 0.0, l));
    }
    return std::make_unique<StepChain>(std::move(steps));
}

} // namespace sweepers
