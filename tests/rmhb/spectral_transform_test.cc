#include "rmhb/spectral_transform.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace rmhb {
namespace {

Eigen::VectorXd Random(int n, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  Eigen::VectorXd v(n);
  for (int i = 0; i < n; ++i) v(i) = u(gen);
  return v;
}

TEST(SpectralTransform, ProjectionInvertsSynthesisPeriodic) {
  const HarmonicBasis basis = HarmonicBasis::Periodic(7);
  for (int M : {15, 16, 29, 64}) {
    SpectralTransform t(basis, Sampling::Uniform(M));
    const Eigen::VectorXd x = Random(basis.num_coefficients(), M);
    Eigen::VectorXd s(M), y(basis.num_coefficients());
    t.Synthesize(x.data(), s.data());
    t.Project(s.data(), y.data());
    EXPECT_LT((x - y).cwiseAbs().maxCoeff(), 1e-14) << "M = " << M;
  }
}

TEST(SpectralTransform, SynthesisMatchesDirectSum) {
  const HarmonicBasis basis = HarmonicBasis::Periodic(4);
  const int M = 13;
  SpectralTransform t(basis, Sampling::Uniform(M));
  const Eigen::VectorXd x = Random(basis.num_coefficients(), 3);
  Eigen::VectorXd s(M);
  t.Synthesize(x.data(), s.data());
  for (int j = 0; j < M; ++j) {
    const double th = 2 * M_PI * j / M;
    double v = x(0);
    for (int k = 1; k <= 4; ++k) v += x(2 * k - 1) * std::cos(k * th) + x(2 * k) * std::sin(k * th);
    EXPECT_NEAR(s(j), v, 1e-14);
  }
}

TEST(SpectralTransform, TorusAndGcdGridsInvertSynthesis) {
  const HarmonicBasis basis = HarmonicBasis::Diamond(2, 3);
  const Eigen::VectorXd x = Random(basis.num_coefficients(), 9);
  for (const Sampling& sampling : {Sampling::Torus({9, 10}), Sampling::Gcd(64, {3, 5})}) {
    SpectralTransform t(basis, sampling);
    Eigen::VectorXd s(t.num_samples()), y(basis.num_coefficients());
    t.Synthesize(x.data(), s.data());
    t.Project(s.data(), y.data());
    EXPECT_LT((x - y).cwiseAbs().maxCoeff(), 1e-13) << sampling.description;
  }
}

TEST(SpectralTransform, RefusesGridTooCoarseForBasis) {
  EXPECT_THROW(SpectralTransform(HarmonicBasis::Periodic(5), Sampling::Uniform(9)),
               std::invalid_argument);
  EXPECT_THROW(SpectralTransform(HarmonicBasis::Periodic(5), Sampling::Uniform(10)),
               std::invalid_argument);  // harmonic 5 on the Nyquist line
}

// E* diag(p) E (and with the derivative map) from the Toeplitz-Hankel formula
// must equal the product formed column by column through the samples.
TEST(SpectralTransform, MultiplicationMatrixMatchesSampledProduct) {
  for (const bool torus : {false, true}) {
    const HarmonicBasis basis = torus ? HarmonicBasis::Diamond(2, 3) : HarmonicBasis::Periodic(6);
    const Sampling sampling = torus ? Sampling::Torus({11, 12}) : Sampling::Uniform(23);
    SpectralTransform t(basis, sampling);
    const int C = basis.num_coefficients();
    const long M = t.num_samples();
    const Eigen::VectorXd p = Random(static_cast<int>(M), 5);
    std::vector<double> rate(basis.size());
    for (int k = 0; k < basis.size(); ++k) rate[k] = basis.Frequency(k, torus ? std::vector<double>{1.0, 1.37} : std::vector<double>{0.8});
    t.Analyze(p.data());
    Eigen::MatrixXd B = Eigen::MatrixXd::Zero(C, C), BD = Eigen::MatrixXd::Zero(C, C);
    t.AddMultiplicationMatrix(1.0, nullptr, B);
    t.AddMultiplicationMatrix(1.0, rate.data(), BD);
    Eigen::VectorXd e(C), d(C), s(M), col(C);
    for (int l = 0; l < C; ++l) {
      e.setZero();
      e(l) = 1;
      t.Synthesize(e.data(), s.data());
      s.array() *= p.array();
      t.Project(s.data(), col.data());
      EXPECT_LT((B.col(l) - col).cwiseAbs().maxCoeff(), 1e-13);
      d.setZero();  // derivative of basis function l
      if (l > 0) {
        const int k = (l + 1) / 2;
        if (l % 2) d(2 * k) = -rate[k];  // cos -> -w sin
        else d(2 * k - 1) = rate[k];     // sin -> w cos
      }
      t.Synthesize(d.data(), s.data());
      s.array() *= p.array();
      t.Project(s.data(), col.data());
      EXPECT_LT((BD.col(l) - col).cwiseAbs().maxCoeff(), 1e-13);
    }
  }
}

// The dense backend (small one-angle grids) and FFTW give the same
// synthesis, projection and multiplication matrix to round-off, on the
// uniform grid and on a GCD-rule grid (harmonics embedded as 3 k).
TEST(SpectralTransform, DenseAndFftwBackendsAgree) {
  struct Case {
    HarmonicBasis basis;
    Sampling sampling;
  };
  for (const Case& c : {Case{HarmonicBasis::Periodic(9), Sampling::Uniform(31)},
                        Case{HarmonicBasis::Periodic(20), Sampling::Uniform(80)},
                        Case{HarmonicBasis::Diamond(2, 2), Sampling::Gcd(40, {3, 5})}}) {
    SpectralTransform dense(c.basis, c.sampling, SpectralTransform::Backend::kDense);
    SpectralTransform fftw(c.basis, c.sampling, SpectralTransform::Backend::kFftw);
    ASSERT_TRUE(dense.dense());
    ASSERT_FALSE(fftw.dense());
    const int C = c.basis.num_coefficients();
    const long M = dense.num_samples();
    const Eigen::VectorXd x = Random(C, 11), p = Random(static_cast<int>(M), 12);
    Eigen::VectorXd s1(M), s2(M), y1(C), y2(C);
    dense.Synthesize(x.data(), s1.data());
    fftw.Synthesize(x.data(), s2.data());
    EXPECT_LT((s1 - s2).cwiseAbs().maxCoeff(), 1e-13) << c.sampling.description;
    dense.Project(p.data(), y1.data());
    fftw.Project(p.data(), y2.data());
    EXPECT_LT((y1 - y2).cwiseAbs().maxCoeff(), 1e-14) << c.sampling.description;
    std::vector<double> rate(c.basis.size());
    for (int k = 0; k < c.basis.size(); ++k) rate[k] = 0.7 * k;
    Eigen::MatrixXd B1 = Eigen::MatrixXd::Zero(C, C), B2 = B1;
    dense.Analyze(p.data());
    fftw.Analyze(p.data());
    dense.AddMultiplicationMatrix(1.0, rate.data(), B1);
    fftw.AddMultiplicationMatrix(1.0, rate.data(), B2);
    EXPECT_LT((B1 - B2).cwiseAbs().maxCoeff(), 1e-13) << c.sampling.description;
  }
  EXPECT_THROW(SpectralTransform(HarmonicBasis::Diamond(2, 2), Sampling::Torus({9, 9}),
                                 SpectralTransform::Backend::kDense),
               std::invalid_argument);
}

// A symmetry's restricted transforms (odd harmonics kept, as the half-wave
// symmetry keeps them) equal the full ones where they are asked, on both
// backends: synthesis of a vector zero elsewhere, projection and the
// multiplication matrix at the kept rows and columns.
TEST(SpectralTransform, RestrictedToSomeHarmonicsEqualsTheFullTransforms) {
  const HarmonicBasis basis = HarmonicBasis::Periodic(11);
  const int C = basis.num_coefficients();
  std::vector<char> odd(basis.size(), 0);
  std::vector<int> some;
  for (int k = 1; k < basis.size(); k += 2) odd[k] = 1;
  for (int c = 0; c < C; ++c)
    if (odd[(c + 1) / 2]) some.push_back(c);
  for (auto backend : {SpectralTransform::Backend::kDense, SpectralTransform::Backend::kFftw}) {
    SpectralTransform t(basis, Sampling::Uniform(48), backend);
    const long M = t.num_samples();
    Eigen::VectorXd x = Eigen::VectorXd::Zero(C);
    const Eigen::VectorXd r = Random(C, 21), p = Random(static_cast<int>(M), 22);
    for (int c : some) x(c) = r(c);
    Eigen::VectorXd full(M), restricted(M);
    t.Synthesize(x.data(), full.data());
    t.SynthesizeSome(x.data(), some, restricted.data());
    EXPECT_LT((full - restricted).cwiseAbs().maxCoeff(), 1e-14);
    Eigen::VectorXd y(C), z = Eigen::VectorXd::Constant(C, 7.0);
    t.Project(p.data(), y.data());
    t.ProjectSome(p.data(), some, z.data());
    for (int c = 0; c < C; ++c)
      if (odd[(c + 1) / 2]) {
        EXPECT_NEAR(z(c), y(c), 1e-14) << c;
      } else if (t.dense()) {
        EXPECT_EQ(z(c), 7.0) << c;  // left as it was
      }
    std::vector<double> rate(basis.size());
    for (int k = 0; k < basis.size(); ++k) rate[k] = 0.9 * k;
    Eigen::MatrixXd B = Eigen::MatrixXd::Zero(C, C), R = Eigen::MatrixXd::Constant(C, C, 5.0);
    t.Analyze(p.data());
    t.AddMultiplicationMatrix(1.0, rate.data(), B);
    t.AddMultiplicationMatrix(1.0, rate.data(), R, odd.data(), odd.data());
    for (int j = 0; j < C; ++j)
      for (int i = 0; i < C; ++i) {
        const bool kept = odd[(i + 1) / 2] && odd[(j + 1) / 2];
        EXPECT_NEAR(R(i, j), kept ? 5.0 + B(i, j) : 5.0, 1e-14) << i << ", " << j;
      }
  }
}

// A grid shifted by half a step (Sampling::half_step) samples what the grid
// twice as fine has at its odd points, through the coarse grid's tables; the
// fine projection is the mean of the grid's and its shifted copies'. One
// angle (both backends, all and some harmonics) and a torus (three copies).
TEST(SpectralTransform, HalfStepCopiesAreTheGridTwiceAsFine) {
  const HarmonicBasis line = HarmonicBasis::Periodic(9);
  const std::vector<int> all = [&] {
    std::vector<int> c(line.num_coefficients());
    for (int i = 0; i < line.num_coefficients(); ++i) c[i] = i;
    return c;
  }();
  const std::vector<int> sines = {2, 4, 8, 12};  // a sine-only symmetry's kept coefficients
  for (auto backend : {SpectralTransform::Backend::kDense, SpectralTransform::Backend::kFftw})
    for (const std::vector<int>& some : {all, sines}) {
      const int M = 21, C = line.num_coefficients();
      Eigen::VectorXd x = Eigen::VectorXd::Zero(C);
      const Eigen::VectorXd r = Random(C, 31), p = Random(2 * M, 32);
      for (int c : some) x(c) = r(c);
      SpectralTransform fine(line, Sampling::Uniform(2 * M), backend);
      SpectralTransform grid(line, Sampling::Uniform(M), backend);
      Sampling half = Sampling::Uniform(M);
      half.half_step = {1};
      SpectralTransform shifted(line, half, backend);
      Eigen::VectorXd f(2 * M), even(M), odd(M), pe(M), po(M);
      fine.Synthesize(x.data(), f.data());
      grid.SynthesizeSome(x.data(), some, even.data());
      shifted.SynthesizeSome(x.data(), some, odd.data());
      for (int j = 0; j < M; ++j) {
        EXPECT_NEAR(even(j), f(2 * j), 1e-14) << j;
        EXPECT_NEAR(odd(j), f(2 * j + 1), 1e-14) << j;
        pe(j) = p(2 * j);
        po(j) = p(2 * j + 1);
        EXPECT_NEAR(shifted.Phase({3}, j), std::fmod(3 * (j + 0.5) * 2 * M_PI / M, 2 * M_PI), 1e-13);
      }
      Eigen::VectorXd y(C), a = Eigen::VectorXd::Constant(C, 7.0), b = Eigen::VectorXd::Constant(C, 7.0);
      fine.Project(p.data(), y.data());
      grid.ProjectSome(pe.data(), some, a.data());
      shifted.ProjectSome(po.data(), some, b.data());
      for (int c = 0; c < C; ++c)
        if (std::find(some.begin(), some.end(), c) != some.end()) {
          EXPECT_NEAR(0.5 * (a(c) + b(c)), y(c), 1e-14) << c;
        } else if (shifted.dense()) {
          EXPECT_EQ(b(c), 7.0) << c;  // left as it was
        }
      EXPECT_THROW(shifted.Analyze(po.data()), std::logic_error);
    }
  const HarmonicBasis torus = HarmonicBasis::Diamond(2, 3);
  const int C = torus.num_coefficients();
  const Eigen::VectorXd x = Random(C, 33);
  SpectralTransform fine(torus, Sampling::Torus({18, 20}));
  Eigen::VectorXd f(18 * 20), y(C), mean = Eigen::VectorXd::Zero(C);
  fine.Synthesize(x.data(), f.data());
  fine.Project(f.data(), y.data());
  for (int copy = 0; copy < 4; ++copy) {
    Sampling sampling = Sampling::Torus({9, 10});
    sampling.half_step = {copy & 1, copy >> 1};
    SpectralTransform t(torus, sampling);
    Eigen::VectorXd s(90), z(C);
    t.Synthesize(x.data(), s.data());
    for (int i = 0; i < 9; ++i)
      for (int j = 0; j < 10; ++j)
        EXPECT_NEAR(s(i * 10 + j), f((2 * i + (copy & 1)) * 20 + 2 * j + (copy >> 1)), 1e-13) << copy;
    t.Project(s.data(), z.data());
    mean += z / 4;
  }
  EXPECT_LT((mean - y).cwiseAbs().maxCoeff(), 1e-13);
  Sampling bad = Sampling::Uniform(21);
  bad.half_step = {2};
  EXPECT_THROW(SpectralTransform(line, bad), std::invalid_argument);
  bad.half_step = {1, 0};
  EXPECT_THROW(SpectralTransform(line, bad), std::invalid_argument);
}

// A constant partial (a linear term): the identity (or D) times the value,
// what the Toeplitz-plus-Hankel assembly gives to round-off, on a one-angle
// and a torus grid.
TEST(SpectralTransform, ConstantMultiplicationIsTheScaledIdentity) {
  struct Case {
    HarmonicBasis basis;
    Sampling sampling;
  };
  for (const Case& c : {Case{HarmonicBasis::Periodic(9), Sampling::Uniform(28)},
                        Case{HarmonicBasis::Diamond(2, 3), Sampling::Torus({12, 12})}}) {
    SpectralTransform t(c.basis, c.sampling);
    const int C = c.basis.num_coefficients();
    const Eigen::VectorXd p = Eigen::VectorXd::Constant(t.num_samples(), -1.7);
    std::vector<double> rate(c.basis.size());
    for (int k = 0; k < c.basis.size(); ++k) rate[k] = 0.3 + 0.8 * k;
    t.Analyze(p.data());
    for (const double* r : {static_cast<const double*>(nullptr), static_cast<const double*>(rate.data())}) {
      Eigen::MatrixXd full = Eigen::MatrixXd::Zero(C, C), constant = full;
      t.AddMultiplicationMatrix(1.0, r, full);
      t.AddConstantMultiplication(-1.7, r, constant);
      EXPECT_LT((full - constant).cwiseAbs().maxCoeff(), 1e-13) << c.sampling.description;
    }
  }
}

// The direct assembly puts each entry of E* diag(p) E (D) where the targets
// say and nowhere else: against the full block, on a GCD grid (one angle, two
// bases) and a periodic one, with a third of the rows and columns dropped and
// the rest scattered into a larger matrix.
TEST(SpectralTransform, DirectAssemblyPutsTheBlocksEntriesWhereTargetsSay) {
  struct Case {
    HarmonicBasis basis;
    Sampling sampling;
  };
  for (const Case& c : {Case{HarmonicBasis::Periodic(7), Sampling::Uniform(31)},
                        Case{HarmonicBasis::Diamond(2, 2), Sampling::Gcd(61, {3, 5})}}) {
    SpectralTransform t(c.basis, c.sampling);
    ASSERT_EQ(t.num_angles(), 1);
    const int C = c.basis.num_coefficients();
    const Eigen::VectorXd p = Random(static_cast<int>(t.num_samples()), 11);
    std::vector<double> rate(c.basis.size());
    for (int k = 0; k < c.basis.size(); ++k) rate[k] = 0.4 + 0.9 * k;
    std::vector<int> rows(C), columns(C);
    for (int i = 0; i < C; ++i) {
      rows[i] = i % 3 == 1 ? -1 : 2 * C - 1 - i;  // reversed, into rows C .. 2C - 1
      columns[i] = i % 3 == 2 ? -1 : i + 3;
    }
    SpectralTransform::Targets targets;
    targets.rows = rows.data();
    targets.columns = columns.data();
    t.Analyze(p.data());
    for (const double* r : {static_cast<const double*>(nullptr), static_cast<const double*>(rate.data())})
      for (bool constant : {false, true}) {
        Eigen::MatrixXd block = Eigen::MatrixXd::Zero(C, C);
        Eigen::MatrixXd direct = Eigen::MatrixXd::Constant(2 * C, C + 3, 0.25), expected = direct;
        if (constant) {
          t.AddConstantMultiplication(-1.3, r, block);
          t.AddConstantMultiplicationTo(-1.3, r, targets, direct);
        } else {
          t.AddMultiplicationMatrix(1.0, r, block);
          t.AddMultiplicationTo(r, targets, direct);
        }
        for (int i = 0; i < C; ++i)
          for (int j = 0; j < C; ++j)
            if (rows[i] >= 0 && columns[j] >= 0) expected(rows[i], columns[j]) += block(i, j);
        // To rounding: each entry is added to 0.25 once, fused or not.
        EXPECT_LT((direct - expected).cwiseAbs().maxCoeff(), 1e-14) << c.sampling.description;
      }
  }
}

}  // namespace
}  // namespace rmhb
