// SPDX-License-Identifier: Apache-2.0
#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>

#include "core/motion_log.h"
#include "random.h"

using namespace sweepers;
using sweepers::test::apply;
using sweepers::test::maxDiff;
using sweepers::test::Rng;
using sweepers::test::seriesExp;

namespace {

// Appendix A.2.2: S = T_c S_s T_-c.
Eigen::Matrix4d scaleAbout(double s, const Eigen::Vector3d& c) {
    Eigen::Matrix4d M = Eigen::Matrix4d::Identity();
    M.topLeftCorner<3, 3>() *= s;
    M.topRightCorner<3, 1>() = (1 - s) * c;
    return M;
}

// Appendix A.3.2: scale by s along unit n about c.
Eigen::Matrix4d axisScaleAbout(double s, const Eigen::Vector3d& n, const Eigen::Vector3d& c) {
    Eigen::Matrix4d M = Eigen::Matrix4d::Identity();
    M.topLeftCorner<3, 3>() += (s - 1) * n * n.transpose();
    M.topRightCorner<3, 1>() = (1 - s) * c.dot(n) * n;
    return M;
}

} // namespace

TEST(MotionLog, UniformScaleLogsMatchAppendixA2) {
    Rng rng(21);
    for (int i = 0; i < 500; ++i) {
        const double s = std::exp(rng.uniform(-1.5, 1.5));
        const Eigen::Vector3d c = rng.vec(-3, 3);
        const Eigen::Matrix4d M = scaleAbout(s, c);
        const MotionLog closed = MotionLog::uniformScale(s, c);
        const MotionLog fromM = MotionLog::log(M);
        EXPECT_EQ(closed.kind(), MotionLog::Kind::Dilation);
        EXPECT_EQ(fromM.kind(), MotionLog::Kind::Dilation);
        EXPECT_LT(maxDiff(closed.matrix(), fromM.matrix()), 1e-12);
        EXPECT_LT(maxDiff(closed.exp(), M), 1e-9);
        EXPECT_LT(maxDiff(seriesExp(fromM.matrix()), M), 1e-9);
    }
}

TEST(MotionLog, NonUniformScaleLogsMatchAppendixA3) {
    Rng rng(22);
    for (int i = 0; i < 500; ++i) {
        const double s = std::exp(rng.uniform(-1.5, 1.5));
        const Eigen::Vector3d n = rng.unit(), c = rng.vec(-3, 3);
        const Eigen::Matrix4d M = axisScaleAbout(s, n, c);
        const MotionLog closed = MotionLog::axisScale(s, n, c);
        const MotionLog fromM = MotionLog::log(M);
        EXPECT_EQ(closed.kind(), MotionLog::Kind::AxisScale);
        EXPECT_EQ(fromM.kind(), MotionLog::Kind::AxisScale);
        EXPECT_LT(maxDiff(closed.matrix(), fromM.matrix()), 1e-10);
        EXPECT_LT(maxDiff(closed.exp(), M), 1e-9);
        EXPECT_LT(maxDiff(seriesExp(fromM.matrix()), M), 1e-9);
        // 3.27: a fraction w of the sub-step moves p by (s^w - 1) ((p - c).n) n.
        const double w = rng.uniform(-1, 1);
        const Eigen::Vector3d p = rng.vec(-3, 3);
        const Eigen::Vector3d expected = p + (std::pow(s, w) - 1) * (p - c).dot(n) * n;
        EXPECT_LT((fromM.applyExp(w, p) - expected).norm(), 1e-12);
    }
}

TEST(MotionLog, ExpOfLogReproducesRandomMotions) {
    Rng rng(23);
    for (int i = 0; i < 1000; ++i) {
        // Rigid, scaled along three axes, and rotated-and-scaled motions.
        const Eigen::Matrix4d R = rng.rigid(2.5, 2.0);
        Eigen::Matrix4d S = Eigen::Matrix4d::Identity();
        const Eigen::Vector3d axis = rng.unit(); // (drawn first: see Rng::rigid)
        const Eigen::Matrix3d Q = Eigen::AngleAxisd(rng.uniform(0, 3), axis).matrix();
        S.topLeftCorner<3, 3>() =
            Q * rng.vec(-1, 1).array().exp().matrix().asDiagonal() * Q.transpose();
        S.topRightCorner<3, 1>() = rng.vec(-1, 1);
        for (const Eigen::Matrix4d& M : {R, S, Eigen::Matrix4d(R * S)}) {
            const MotionLog L = MotionLog::log(M);
            EXPECT_LT(maxDiff(L.exp(), M), 1e-9);
            EXPECT_LT(maxDiff(seriesExp(L.matrix()), M), 1e-9);
        }
    }
}

TEST(MotionLog, KindsJoinAndApplyExpMatchesTheMatrix) {
    const MotionLog t = MotionLog::translation({1, 0, 0});
    const MotionLog r = Twist::rotation({0, 0, 1}, 0.5, {1, 1, 0});
    const MotionLog d = MotionLog::uniformScale(1.5, {0, 1, 0});
    EXPECT_EQ((t + t).kind(), MotionLog::Kind::Translation);
    EXPECT_EQ((t + r).kind(), MotionLog::Kind::Twist);
    EXPECT_EQ((t + d).kind(), MotionLog::Kind::Dilation);
    EXPECT_EQ((r + d).kind(), MotionLog::Kind::General);
    const MotionLog a = MotionLog::axisScale(0.7, Eigen::Vector3d(1, 2, -2), {0.5, 0, 1});
    const MotionLog b = MotionLog::axisScale(1.3, {0, 1, 0}, {0, 0, 0});
    EXPECT_EQ(a.kind(), MotionLog::Kind::AxisScale);
    EXPECT_EQ((t * 0.3 + a * 0.5).kind(), MotionLog::Kind::AxisScale);
    EXPECT_EQ((a * 0.4 + a * -1.5).kind(), MotionLog::Kind::AxisScale);
    EXPECT_EQ((a + b).kind(), MotionLog::Kind::General);
    EXPECT_EQ((a + d).kind(), MotionLog::Kind::General);
    EXPECT_EQ((t * 0.3 + r * 0.2 + a * 0.5).kind(), MotionLog::Kind::General);
    // Rank one but not symmetric: shears along n (a n m^T) are no scale along an axis.
    Eigen::Matrix4d shear = Eigen::Matrix4d::Zero();
    shear.topLeftCorner<3, 3>() = Eigen::Vector3d(0, 0, 1) * Eigen::RowVector3d(0.3, 0, 0.5);
    const MotionLog sheared = MotionLog::fromMatrix(shear);
    EXPECT_EQ(sheared.kind(), MotionLog::Kind::General);
    Rng rng(24);
    for (const MotionLog& L :
         {t, r, d, a, b, MotionLog(r + d), MotionLog(t * 0.3 + a * 0.5), MotionLog(a + b),
          MotionLog(a * 0.4 + a * -1.5), MotionLog(a * 1e-9 + t),
          MotionLog(t * 0.3 + r * 0.2 + a * 0.5), sheared}) {
        const Eigen::Matrix4d E = seriesExp(L.matrix());
        EXPECT_LT(maxDiff(L.exp(), E), 1e-12);
        for (int i = 0; i < 20; ++i) {
            const Eigen::Vector3d p = rng.vec(-2, 2);
            EXPECT_LT((L.applyExp(p) - apply(E, p)).norm(), 1e-12);
        }
    }
}

TEST(MotionLog, BlendOfTwistsStaysOnTheClosedForm) {
    // 7.60: a weighted sum of twists is a twist, exponentiated in closed form.
    const MotionLog a = Twist::rotation({0, 0, 1}, 0.8, {1, 0, 0});
    const MotionLog b = Twist::screw({1, 0, 0}, 0.4, {0, 1, 0}, 0.3);
    const MotionLog mix = a * 0.25 + b * 0.75;
    EXPECT_EQ(mix.kind(), MotionLog::Kind::Twist);
    EXPECT_LT(maxDiff(mix.exp(), seriesExp(mix.matrix())), 1e-12);
}

TEST(MotionLog, RefusesMotionsWithoutARealLog) {
    Eigen::Matrix4d mirror = Eigen::Matrix4d::Identity();
    mirror(0, 0) = -1;
    EXPECT_THROW(MotionLog::log(mirror), std::domain_error);
    Eigen::Matrix4d flat = Eigen::Matrix4d::Identity();
    flat(2, 2) = 0;
    EXPECT_THROW(MotionLog::log(flat), std::domain_error);
    Eigen::Matrix4d nan = Eigen::Matrix4d::Identity();
    nan(0, 3) = std::nan("");
    EXPECT_THROW(MotionLog::log(nan), std::domain_error);
    Eigen::Matrix4d projective = Eigen::Matrix4d::Identity();
    projective(3, 0) = 0.5;
    EXPECT_THROW(MotionLog::log(projective), std::domain_error);
}

TEST(MotionLog, ConjugationByAMirrorMirrorsTheMotion) {
    Eigen::Matrix4d R = Eigen::Matrix4d::Identity();
    R(0, 0) = -1;
    Rng rng(25);
    for (int i = 0; i < 100; ++i) {
        const Eigen::Matrix4d M = rng.rigid(2.0, 1.0);
        const MotionLog L = MotionLog::log(M).conjugated(R);
        EXPECT_EQ(L.kind(), MotionLog::Kind::Twist);
        EXPECT_LT(maxDiff(L.exp(), R * M * R), 1e-9);
    }
}
