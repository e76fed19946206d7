// Anisotropies recovered from synthetic contact sets drawn (seeded) from known densities
// E(n) = (1 + a^r:nn)/4π, f̄ⁿ = f0 (1 + aⁿ:nn), f̄ᵗ = f0 (aᵗ n − (aᵗ:nn) n), and branch vectors
// l̄ⁿ = l0 (1 + aᵛ:nn), l̄ᵗ = l0 (aᵗᵃᵘ n − ...). The expected standard error of each estimate is
// derived here by the delta method (the linearisation of the estimator around the sample, one
// influence term per contact), checked against the scatter of independent replicas, and each
// estimate must lie within 4 standard errors of the true value.
#include <gtest/gtest.h>

#include <random>

#include "lab/micromechanics.hpp"

using namespace grainlab;
using namespace grainlab::lab;

namespace {

constexpr double kFourPi = 4.0 * kPi;

Mat3 axi(double a) { return Mat3(Vec3(-a / 3, -a / 3, 2 * a / 3).asDiagonal()); }
Mat3 dev(const Mat3& m) { return m - m.trace() / 3 * Mat3::Identity(); }

struct Model {
  Mat3 ar = Mat3::Zero(), an = Mat3::Zero(), at = Mat3::Zero(), av = Mat3::Zero(), atau = Mat3::Zero();
  std::optional<Tensor4> ar4, an4;
  double f0 = 10.0, l0 = 2e-3;
};

Tensor4 scaledDeviator4OfAxis(const Vec3& e, double amplitude) {
  Tensor4 t{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k)
        for (int l = 0; l < 3; ++l) t[((i * 3 + j) * 3 + k) * 3 + l] = e[i] * e[j] * e[k] * e[l];
  Tensor4 d = deviator4(t);
  for (double& v : d) v *= amplitude * 35.0 / 8.0;  // value `amplitude` along e (dev4(e⁴)::e⁴ = 8/35)
  return d;
}

Vec3 uniformDirection(std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  return Vec3(g(rng), g(rng), g(rng)).normalized();
}

Vec3 tangentNoise(std::mt19937_64& rng, const Vec3& n, double scale) {
  std::normal_distribution<double> g;
  const Vec3 v(g(rng), g(rng), g(rng));
  return scale * (v - v.dot(n) * n);
}

// Direction drawn from (1 + a:nn + A::nnnn)/4π by rejection.
Vec3 drawDirection(std::mt19937_64& rng, const Mat3& a, const std::optional<Tensor4>& a4) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double bound = 2.0;
  for (;;) {
    const Vec3 n = uniformDirection(rng);
    double e = 1.0 + n.dot(a * n);
    if (a4) e += contract4(*a4, n);
    if (e > bound) throw std::logic_error("rejection bound too low");
    if (u(rng) * bound < e) return n;
  }
}

MicroNetwork synthetic(const Model& m, int contacts, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::gamma_distribution<double> gamma(2.0, 0.5);  // mean 1, variance 1/2
  std::uniform_real_distribution<double> w(0.8, 1.2);
  std::uniform_int_distribution<int> pick(0, 999);
  MicroNetwork net;
  net.volume = 1e-3;
  for (int i = 0; i < 1000; ++i) {
    MicroParticle p;
    p.id = i;
    p.radius = 1e-3;
    net.particles.push_back(p);
  }
  for (int c = 0; c < contacts; ++c) {
    const Vec3 n = drawDirection(rng, m.ar, m.ar4);
    double fnMean = 1.0 + n.dot(m.an * n);
    if (m.an4) fnMean += contract4(*m.an4, n);
    const double fn = m.f0 * fnMean * gamma(rng);
    const Vec3 ft = m.f0 * (m.at * n - n.dot(m.at * n) * n) * gamma(rng) + tangentNoise(rng, n, 0.2 * m.f0);
    const double ln = m.l0 * (1.0 + n.dot(m.av * n)) * w(rng);
    const Vec3 lt = m.l0 * (m.atau * n - n.dot(m.atau * n) * n) * w(rng) + tangentNoise(rng, n, 0.02 * m.l0);
    const Vec3 l = ln * n + lt;
    MicroContact k;
    k.a = pick(rng);
    k.b = (k.a + 1 + pick(rng) % 999) % 1000;
    k.normal = n;
    k.force = fn * n + ft;
    k.branchA = 0.5 * l;
    k.branchB = -0.5 * l;
    net.contacts.push_back(k);
  }
  return net;
}

// Standard errors by the delta method. The library fits, by area-weighted least squares, the
// patch averages of g(n) = nᵀCn (C symmetric: 6 coefficients) to the class means ḡ_k, and of
// t(n) = B n − (nᵀBn) n (B symmetric traceless: 5) to the tangential class means; the
// coefficients are linear in the class means: δc = (Σ_k w_k b_k b_kᵀ)⁻¹ Σ_k w_k b_k δḡ_k. One
// contact changes the means of its two classes (n and −n) by (g_c − ḡ_k)/C_k. From C:
// g0 = tr C/3 and a = dev(C)/g0, so δa = dev(δC)/g0 − a·δg0/g0; from B: aᵗ = B/g0. Fabric:
// a^r = 15/2 dev<nn>, influence 15/2 (dev(nn) − dev R)/N. Var = Σ_c influence_c².
class LinearisedFits {
 public:
  explicit LinearisedFits(const OrientationClasses& oc) : oc_(oc) {
    E_[0] << 1, 0, 0, 0, 0, 0, 0, 0, -1;
    E_[1] << 0, 0, 0, 0, 1, 0, 0, 0, -1;
    E_[2] << 0, 1, 0, 1, 0, 0, 0, 0, 0;
    E_[3] << 0, 0, 1, 0, 0, 0, 1, 0, 0;
    E_[4] << 0, 0, 0, 0, 0, 1, 0, 1, 0;
    Eigen::Matrix<double, 6, 6> ns = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 5, 5> nt = Eigen::Matrix<double, 5, 5>::Zero();
    for (std::size_t k = 0; k < oc.size(); ++k) {
      ns += oc.area(k) * scalarRow(k) * scalarRow(k).transpose();
      const auto t = tangentialRows(k);
      nt += oc.area(k) * t.transpose() * t;
    }
    scalarInverse_ = ns.inverse();
    tangentialInverse_ = nt.inverse();
  }
  // Basis of g: C = [[c0, c3, c4], [c3, c1, c5], [c4, c5, c2]]; its patch averages.
  Eigen::Matrix<double, 6, 1> scalarRow(std::size_t k) const {
    const Mat3 m = oc_.secondMoment(k) / oc_.area(k);
    Eigen::Matrix<double, 6, 1> r;
    r << m(0, 0), m(1, 1), m(2, 2), 2 * m(0, 1), 2 * m(0, 2), 2 * m(1, 2);
    return r;
  }
  Eigen::Matrix<double, 3, 5> tangentialRows(std::size_t k) const {
    const Vec3 m1 = oc_.firstMoment(k) / oc_.area(k);
    Eigen::Matrix<double, 3, 5> rows;
    for (int b = 0; b < 5; ++b) {
      Vec3 v = E_[b] * m1;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          for (int l = 0; l < 3; ++l) v[i] -= E_[b](j, l) * oc_.thirdMoment(k)[(j * 3 + l) * 3 + i] / oc_.area(k);
      rows.col(b) = v;
    }
    return rows;
  }
  // δC from a change δḡ_k of one class mean.
  Mat3 dC(std::size_t k, double dg) const {
    const Eigen::Matrix<double, 6, 1> c = scalarInverse_ * scalarRow(k) * (oc_.area(k) * dg);
    Mat3 C;
    C << c[0], c[3], c[4], c[3], c[1], c[5], c[4], c[5], c[2];
    return C;
  }
  Mat3 dB(std::size_t k, const Vec3& dt) const {
    const Eigen::Matrix<double, 5, 1> b = tangentialInverse_ * tangentialRows(k).transpose() * (oc_.area(k) * dt);
    Mat3 B = Mat3::Zero();
    for (int i = 0; i < 5; ++i) B += b[i] * E_[i];
    return B;
  }

 private:
  const OrientationClasses& oc_;
  std::array<Mat3, 5> E_;
  Eigen::Matrix<double, 6, 6> scalarInverse_;
  Eigen::Matrix<double, 5, 5> tangentialInverse_;
};

struct StandardErrors {
  Mat3 ar = Mat3::Zero(), an = Mat3::Zero(), at = Mat3::Zero(), av = Mat3::Zero(), atau = Mat3::Zero();
};

StandardErrors deltaMethod(const MicroNetwork& net, const MicroAnalysis& m, const OrientationClasses& oc) {
  const LinearisedFits fits(oc);
  const auto& ca = m.classes;
  const double nc = static_cast<double>(net.contacts.size());
  const double f0 = *m.f0, l0 = *m.l0;
  StandardErrors var;
  for (const MicroContact& k : net.contacts) {
    const Vec3 n = k.normal;
    const Vec3 l = k.branchA - k.branchB;
    const double fn = k.force.dot(n), ln = l.dot(n);
    const Vec3 ft = k.force - fn * n, lt = l - ln * n;
    var.ar += ((7.5 * dev(n * n.transpose()) - m.ar->tensor) / nc).cwiseAbs2();
    Mat3 dCn = Mat3::Zero(), dBt = Mat3::Zero(), dCl = Mat3::Zero(), dBl = Mat3::Zero();
    for (int side : {1, -1}) {
      const std::size_t c = oc.classOf(side * n);
      const double C = static_cast<double>(ca.count[c]);
      dCn += fits.dC(c, (fn - ca.meanNormalForce[c]) / C);
      dBt += fits.dB(c, (side * ft - ca.meanTangentialForce[c]) / C);
      dCl += fits.dC(c, (ln - ca.meanBranchNormal[c]) / C);
      dBl += fits.dB(c, (side * lt - ca.meanBranchTangential[c]) / C);
    }
    const double df0 = dCn.trace() / 3, dl0 = dCl.trace() / 3;
    var.an += (dev(dCn) / f0 - m.an->tensor * df0 / f0).cwiseAbs2();
    var.at += (dBt / f0 - m.at->tensor * df0 / f0).cwiseAbs2();
    var.av += (dev(dCl) / l0 - m.av->tensor * dl0 / l0).cwiseAbs2();
    var.atau += (dBl / l0 - m.atau->tensor * dl0 / l0).cwiseAbs2();
  }
  return {var.ar.cwiseSqrt(), var.an.cwiseSqrt(), var.at.cwiseSqrt(), var.av.cwiseSqrt(), var.atau.cwiseSqrt()};
}

void expectWithin4Sigma(const Mat3& estimate, const Mat3& truth, const Mat3& se, const char* what) {
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j)
      EXPECT_LE(std::abs(estimate(i, j) - truth(i, j)), 4.0 * se(i, j))
          << what << "(" << i << "," << j << ") = " << estimate(i, j) << ", true " << truth(i, j) << ", se "
          << se(i, j);
}

Model triaxialModel() {
  Model m;
  m.ar = axi(0.45);
  m.an = axi(0.6);
  m.at = axi(0.15);
  // A little off-axis content too, so that shear components are tested as well.
  m.ar(0, 2) = m.ar(2, 0) = 0.08;
  m.an(1, 2) = m.an(2, 1) = -0.1;
  m.at(0, 1) = m.at(1, 0) = 0.05;
  return m;
}

}  // namespace

TEST(Anisotropy, RecoversKnownSecondOrderDensities) {
  const Model model = triaxialModel();
  const MicroAnalyzer analyzer;
  const MicroNetwork net = synthetic(model, 40000, 1);
  const MicroAnalysis m = analyzer.analyse(net);
  ASSERT_TRUE(m.ar && m.an && m.at && m.av && m.f0);
  EXPECT_EQ(m.emptyClasses, 0u);
  const StandardErrors se = deltaMethod(net, m, analyzer.classes());
  expectWithin4Sigma(m.ar->tensor, model.ar, se.ar, "a^r");
  expectWithin4Sigma(m.an->tensor, model.an, se.an, "a^n");
  expectWithin4Sigma(m.at->tensor, model.at, se.at, "a^t");
  expectWithin4Sigma(m.av->tensor, model.av, se.av, "a^v");
  // The standard errors are small enough for the test to mean something (a factor-2 error in
  // any definition is tens of sigma away).
  EXPECT_LT(se.ar.maxCoeff(), 0.02);
  EXPECT_LT(se.an.maxCoeff(), 0.03);
  EXPECT_LT(se.at.maxCoeff(), 0.01);
  EXPECT_NEAR(*m.f0, model.f0, 4 * 0.01 * model.f0);
  EXPECT_NEAR(*m.l0, model.l0, 4 * 0.002 * model.l0);
}

TEST(Anisotropy, StandardErrorsMatchTheScatterOfReplicas) {
  // 100 independent samples of 5000 contacts: the standardised errors z = (â − a)/se must have
  // mean ≈ 0 (|mean| < 0.45: 4.5/√100, room for the classes' small discretisation bias) and
  // standard deviation ≈ 1 (0.75..1.3 holds the sample SD of 100 normal values with room).
  const Model model = triaxialModel();
  const MicroAnalyzer analyzer;
  const int replicas = 100;
  struct Component {
    const char* name;
    int i, j;
    std::vector<double> z;
  };
  std::vector<Component> comps{{"ar_zz", 2, 2, {}}, {"an_zz", 2, 2, {}}, {"at_zz", 2, 2, {}},
                               {"an_yz", 1, 2, {}}, {"at_xy", 0, 1, {}}, {"ar_xz", 0, 2, {}}};
  for (int r = 0; r < replicas; ++r) {
    const MicroNetwork net = synthetic(model, 5000, 1000 + r);
    const MicroAnalysis m = analyzer.analyse(net);
    const StandardErrors se = deltaMethod(net, m, analyzer.classes());
    comps[0].z.push_back((m.ar->tensor(2, 2) - model.ar(2, 2)) / se.ar(2, 2));
    comps[1].z.push_back((m.an->tensor(2, 2) - model.an(2, 2)) / se.an(2, 2));
    comps[2].z.push_back((m.at->tensor(2, 2) - model.at(2, 2)) / se.at(2, 2));
    comps[3].z.push_back((m.an->tensor(1, 2) - model.an(1, 2)) / se.an(1, 2));
    comps[4].z.push_back((m.at->tensor(0, 1) - model.at(0, 1)) / se.at(0, 1));
    comps[5].z.push_back((m.ar->tensor(0, 2) - model.ar(0, 2)) / se.ar(0, 2));
  }
  for (const auto& c : comps) {
    double mean = 0.0, sq = 0.0;
    for (double z : c.z) mean += z / replicas;
    for (double z : c.z) sq += (z - mean) * (z - mean) / (replicas - 1);
    EXPECT_LT(std::abs(mean), 0.45) << c.name;
    EXPECT_GT(std::sqrt(sq), 0.75) << c.name;
    EXPECT_LT(std::sqrt(sq), 1.3) << c.name;
  }
}

TEST(Anisotropy, IsotropicSetIsConsistentWithZero) {
  const Model model;  // all anisotropies zero
  const MicroAnalyzer analyzer;
  const MicroNetwork net = synthetic(model, 30000, 77);
  const MicroAnalysis m = analyzer.analyse(net);
  const StandardErrors se = deltaMethod(net, m, analyzer.classes());
  expectWithin4Sigma(m.ar->tensor, Mat3::Zero(), se.ar, "a^r");
  expectWithin4Sigma(m.an->tensor, Mat3::Zero(), se.an, "a^n");
  expectWithin4Sigma(m.at->tensor, Mat3::Zero(), se.at, "a^t");
  // Magnitudes: √(3/2 a:a) of pure noise has mean ≈ √(3/2 Σ se²); 3 times that is far out.
  auto noise = [](const Mat3& s) { return std::sqrt(1.5 * s.cwiseAbs2().sum()); };
  EXPECT_LT(std::abs(m.ar->magnitude), 3 * noise(se.ar));
  EXPECT_LT(std::abs(m.an->magnitude), 3 * noise(se.an));
  EXPECT_LT(std::abs(m.at->magnitude), 3 * noise(se.at));
  // And the stress rebuilt from them is isotropic to the same accuracy.
  EXPECT_LT(std::abs(*m.qOverPSff), 0.4 * 3 * (noise(se.ar) + noise(se.an) + 1.5 * noise(se.at)));
}

TEST(Anisotropy, SffStressMatchesTheContactStressOfTheSample) {
  // In the synthetic model force and branch are independent given n, so the network stress
  // (1/V) Σ f⊗l converges to m_v f0 l0 ∫E F̂⊗L̂ exactly: the rebuilt stress must agree to within
  // the sampling error of the sum (about 1/√N ≈ 0.3 % per component here, so 1.5 % is > 4σ).
  Model model = triaxialModel();
  model.av = axi(0.1);
  model.atau = axi(0.05);
  const MicroAnalysis m = MicroAnalyzer().analyse(synthetic(model, 100000, 5));
  EXPECT_LT(*m.sffError, 0.015);
  // The first-order relation misses the cross terms (a^r a^n ≈ 0.27 here): measurably worse.
  const double linearError = (*m.stressSffLinear - m.stressParticleContacts).norm() / m.stressParticleContacts.norm();
  EXPECT_GT(linearError, 2 * *m.sffError);
  EXPECT_NEAR(*m.qOverPSff, *qOverP(m.stressParticleContacts, 2), 0.02);
}

TEST(Anisotropy, BranchAndParticleOrientationForEllipsoids) {
  Model model = triaxialModel();
  model.av = axi(-0.2);
  model.atau = axi(0.1);
  model.atau(0, 2) = model.atau(2, 0) = 0.04;
  const MicroAnalyzer analyzer;
  MicroNetwork net = synthetic(model, 40000, 8);
  // Long axes drawn from (1 + a^E:uu)/4π with a^E = axi(−0.5): lying flat, as after deposition.
  std::mt19937_64 rng(4);
  Mat3 aE = axi(-0.5);
  Mat3 uu = Mat3::Zero();
  std::vector<Vec3> axes;
  for (auto& p : net.particles) {
    p.shape = MicroParticle::Shape::Ellipsoid;
    p.semiAxes = Vec3(2e-3, 1e-3, 1e-3);
    p.longAxis = drawDirection(rng, aE, std::nullopt);
    axes.push_back(p.longAxis);
  }
  const MicroAnalysis m = analyzer.analyse(net);
  ASSERT_TRUE(m.aE && m.atau);
  EXPECT_TRUE(m.nonSpherical);
  const StandardErrors se = deltaMethod(net, m, analyzer.classes());
  expectWithin4Sigma(m.av->tensor, model.av, se.av, "a^v");
  expectWithin4Sigma(m.atau->tensor, model.atau, se.atau, "a^tau");
  // a^E = 15/2 dev<uu>; standard error 15/2 · sd(u_i u_j)/√Np.
  Mat3 mean = Mat3::Zero(), sq = Mat3::Zero();
  for (const Vec3& u : axes) mean += u * u.transpose() / axes.size();
  for (const Vec3& u : axes) sq += (u * u.transpose() - mean).cwiseAbs2() / axes.size();
  expectWithin4Sigma(m.aE->tensor, aE, 7.5 * sq.cwiseSqrt() / std::sqrt(double(axes.size())), "a^E");
}

TEST(Anisotropy, FourthOrderTermsRecovered) {
  Model model = triaxialModel();
  model.ar4 = scaledDeviator4OfAxis(Vec3::UnitZ(), 0.3);
  model.an4 = scaledDeviator4OfAxis(Vec3(1, 0, 1).normalized(), -0.25);
  MicroOptions opt;
  opt.fourthOrder = true;
  const MicroAnalyzer analyzer(opt);
  const MicroNetwork net = synthetic(model, 60000, 21);
  const MicroAnalysis m = analyzer.analyse(net);
  ASSERT_TRUE(m.ar4 && m.an4);
  // Second order unchanged by the fourth-order content (orthogonal harmonics).
  const StandardErrors se = deltaMethod(net, m, analyzer.classes());
  expectWithin4Sigma(m.ar->tensor, model.ar, se.ar, "a^r");
  expectWithin4Sigma(m.an->tensor, model.an, se.an, "a^n");
  // Fourth order, a^(4)r = 315/8 dev4(<nnnn>): influence of a contact 315/8 (dev4(nnnn) − mean)/N.
  const double nc = static_cast<double>(net.contacts.size());
  Tensor4 varR{};
  std::vector<Tensor4> perContact;
  for (const MicroContact& k : net.contacts) {
    Tensor4 t{};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        for (int a = 0; a < 3; ++a)
          for (int b = 0; b < 3; ++b)
            t[((i * 3 + j) * 3 + a) * 3 + b] = k.normal[i] * k.normal[j] * k.normal[a] * k.normal[b];
    perContact.push_back(deviator4(t));
  }
  for (const Tensor4& t : perContact)
    for (int q = 0; q < 81; ++q) varR[q] += std::pow((315.0 / 8.0 * t[q] - (*m.ar4)[q]) / nc, 2);
  for (int q = 0; q < 81; ++q)
    EXPECT_LE(std::abs((*m.ar4)[q] - (*model.ar4)[q]), 4 * std::sqrt(varR[q]) + 1e-12) << "a^r4 component " << q;
  // a^(4)n: the standard error from the scatter of 30 independent replicas; their mean must lie
  // within 4 standard errors of the mean (sd/√30) of the truth.
  const int replicas = 30;
  Tensor4 mean{}, sq{};
  std::vector<Tensor4> values;
  for (int r = 0; r < replicas; ++r) values.push_back(*analyzer.analyse(synthetic(model, 20000, 500 + r)).an4);
  for (const Tensor4& v : values)
    for (int q = 0; q < 81; ++q) mean[q] += v[q] / replicas;
  for (const Tensor4& v : values)
    for (int q = 0; q < 81; ++q) sq[q] += std::pow(v[q] - mean[q], 2) / (replicas - 1);
  for (int q = 0; q < 81; ++q)
    EXPECT_LE(std::abs(mean[q] - (*model.an4)[q]), 4 * std::sqrt(sq[q] / replicas) + 1e-12) << "a^n4 component " << q;
  // Meaningful: the terms are many standard errors from zero.
  EXPECT_GT(norm4(*m.ar4), 0.5 * norm4(*model.ar4));
  EXPECT_GT(norm4(*m.an4), 0.5 * norm4(*model.an4));
}

TEST(Anisotropy, EmptyClassesDropOutOfTheFit) {
  // 300 contacts over 384 classes leave many classes empty: the fit uses the others; the estimate
  // must be finite, the empty classes counted, and near the truth (loose: the sample is tiny).
  const Model model = triaxialModel();
  const MicroAnalysis m = MicroAnalyzer().analyse(synthetic(model, 300, 3));
  EXPECT_GT(m.emptyClasses, 50u);
  ASSERT_TRUE(m.an && m.at);
  EXPECT_TRUE(m.an->tensor.allFinite());
  EXPECT_NEAR(m.an->tensor(2, 2), model.an(2, 2), 0.35);
  EXPECT_TRUE(std::isnan(m.classes.meanNormalForce[std::find(m.classes.count.begin(), m.classes.count.end(), 0u) -
                                                    m.classes.count.begin()]));
}

TEST(Anisotropy, NoContactsGivesNullsNotZeros) {
  MicroNetwork net;
  net.volume = 1.0;
  MicroParticle p;
  net.particles = {p};
  const MicroAnalysis m = MicroAnalyzer().analyse(net);
  EXPECT_FALSE(m.ar.has_value());
  EXPECT_FALSE(m.f0.has_value());
  EXPECT_FALSE(m.qOverPSff.has_value());
  const auto row = microRowValues(m, {});
  EXPECT_EQ(row.size(), microColumnNames({}).size());
  EXPECT_FALSE(row[0].has_value());  // Z_mech
  EXPECT_TRUE(row[1].has_value());   // rattler fraction = 1 is measured
  EXPECT_DOUBLE_EQ(*row[1], 1.0);
}
