// Lightning against Poisson statistics, the published stroke statistics it is configured with,
// seed 004's bolt constraints, the inverse-square law and exact integrals of its light curves.
#include "scene/sky/lightning.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include "scene/config/config.h"
#include "scene/core/error.h"

namespace seasense::scene {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;

LightningSettings OneCell(double rate_perMin, double radius_m = 3000.0) {
    LightningSettings s;
    StormCellSettings cell;
    cell.center_m = {2000.0, -5000.0, 0.0};
    cell.radius_m = radius_m;
    cell.cloudBase_m = 1500.0;
    cell.flashRate_perMin = rate_perMin;
    s.cells.push_back(cell);
    return s;
}

// Flashes that start inside [t0, t1).
std::vector<Flash> StartingIn(const Lightning& lightning, double t0, double t1) {
    std::vector<Flash> out;
    for (Flash& f : lightning.FlashesBetween(t0, t1))
        if (f.start_s >= t0 && f.start_s < t1) out.push_back(std::move(f));
    return out;
}

bool SameFlash(const Flash& a, const Flash& b) {
    if (a.id != b.id || a.cell != b.cell || a.start_s != b.start_s || a.end_s != b.end_s ||
        a.root_m != b.root_m || a.strokes.size() != b.strokes.size())
        return false;
    for (size_t i = 0; i < a.strokes.size(); ++i)
        if (a.strokes[i].start_s != b.strokes[i].start_s ||
            a.strokes[i].peakPower_W != b.strokes[i].peakPower_W)
            return false;
    return true;
}

TEST(Lightning, FlashCountOverLongWindowMatchesRate) {
    // A Poisson process of rate r over T has mean and variance r T: the count lies within
    // 3 sigma, and counts in disjoint minutes have a dispersion index (variance / mean) near 1.
    for (uint64_t seed : {1u, 7u, 12345u}) {
        const double rate_perMin = 4.0;
        const double T_s = 4.0 * 3600.0;
        const Lightning lightning(OneCell(rate_perMin), seed);
        const std::vector<Flash> flashes = StartingIn(lightning, 0.0, T_s);
        const double expected = rate_perMin / 60.0 * T_s;
        EXPECT_LE(std::abs(double(flashes.size()) - expected), 3.0 * std::sqrt(expected))
            << "seed " << seed;

        std::vector<double> perMinute(size_t(T_s / 60.0), 0.0);
        for (const Flash& f : flashes) perMinute[size_t(f.start_s / 60.0)] += 1.0;
        double mean = 0.0;
        for (double n : perMinute) mean += n;
        mean /= double(perMinute.size());
        double variance = 0.0;
        for (double n : perMinute) variance += (n - mean) * (n - mean);
        variance /= double(perMinute.size() - 1);
        // The dispersion index of 240 Poisson counts has standard error sqrt(2/239) ~ 0.09.
        EXPECT_NEAR(variance / mean, 1.0, 0.3) << "seed " << seed;
    }
}

TEST(Lightning, ZeroRateGivesNoFlashes) {
    const Lightning lightning(OneCell(0.0), 3);
    EXPECT_TRUE(lightning.FlashesBetween(0.0, 3600.0).empty());
}

TEST(Lightning, AnswersDoNotDependOnQueryOrderOrHistory) {
    LightningSettings settings = OneCell(20.0);
    StormCellSettings second = settings.cells[0];
    second.center_m = {-8000.0, 4000.0, 0.0};
    second.flashRate_perMin = 10.0;
    settings.cells.push_back(second);
    const Lightning a(settings, 99);
    const Lightning b(settings, 99);

    std::vector<double> times;
    for (int i = 0; i < 200; ++i) times.push_back(0.1 * i + 0.013 * (i % 7));
    std::vector<std::vector<Flash>> forward;
    for (double t : times) forward.push_back(a.ActiveFlashes(t));
    // Ask b in reverse order, after an unrelated far-future query.
    (void)b.FlashesBetween(1e6, 1e6 + 100.0);
    std::vector<std::vector<Flash>> backward(times.size());
    for (size_t i = times.size(); i-- > 0;) backward[i] = b.ActiveFlashes(times[i]);

    size_t active = 0;
    for (size_t i = 0; i < times.size(); ++i) {
        ASSERT_EQ(forward[i].size(), backward[i].size()) << "t = " << times[i];
        for (size_t j = 0; j < forward[i].size(); ++j)
            EXPECT_TRUE(SameFlash(forward[i][j], backward[i][j]));
        active += forward[i].size();
    }
    EXPECT_GT(active, 0u);  // the comparison saw flashes

    // The active set at t is exactly the flashes of a long window that span t.
    const std::vector<Flash> all = a.FlashesBetween(-10.0, 30.0);
    for (size_t i = 0; i < times.size(); ++i) {
        size_t spanning = 0;
        for (const Flash& f : all)
            if (f.start_s <= times[i] && f.end_s >= times[i]) ++spanning;
        EXPECT_EQ(spanning, forward[i].size());
    }

    // The same flash grows the same bolt; another seed gives other flashes.
    ASSERT_FALSE(all.empty());
    const Bolt b1 = a.GrowBolt(all.front());
    const Bolt b2 = b.GrowBolt(all.front());
    ASSERT_EQ(b1.segments.size(), b2.segments.size());
    for (size_t i = 0; i < b1.segments.size(); ++i) {
        EXPECT_EQ(b1.segments[i].a_m, b2.segments[i].a_m);
        EXPECT_EQ(b1.segments[i].b_m, b2.segments[i].b_m);
    }
    const Lightning other(settings, 100);
    const std::vector<Flash> otherAll = other.FlashesBetween(-10.0, 30.0);
    ASSERT_FALSE(otherAll.empty());
    EXPECT_NE(otherAll.front().start_s, all.front().start_s);
}

TEST(Lightning, BoltsStayInVolumeKeepAnglesAndReachTheSurface) {
    // A narrow cell (radius just above the maximum branch length) stresses the confinement.
    LightningSettings settings = OneCell(30.0, 150.0);
    settings.cells[0].center_m.z = 12.0;  // struck surface above the datum
    settings.bolt.branchAngleMin_rad = 10.0 * kDeg;
    settings.bolt.branchAngleMax_rad = 40.0 * kDeg;
    settings.bolt.branchLengthMin_m = 20.0;
    settings.bolt.branchLengthMax_m = 80.0;
    settings.bolt.density = 0.6;
    const Lightning lightning(settings, 5);
    const StormCellSettings& cell = settings.cells[0];
    const std::vector<Flash> flashes = StartingIn(lightning, 0.0, 600.0);
    ASSERT_GE(flashes.size(), 100u);
    size_t branchSegments = 0;
    for (const Flash& f : flashes) {
        const Bolt bolt = lightning.GrowBolt(f);
        ASSERT_FALSE(bolt.segments.empty());
        // The main channel is continuous from the root at the cloud base to the surface.
        EXPECT_EQ(bolt.segments.front().a_m, f.root_m);
        EXPECT_DOUBLE_EQ(f.root_m.z, cell.cloudBase_m);
        size_t mainCount = 0;
        while (mainCount < bolt.segments.size() && bolt.segments[mainCount].mainChannel)
            ++mainCount;
        for (size_t i = 1; i < mainCount; ++i)
            EXPECT_EQ(bolt.segments[i].a_m, bolt.segments[i - 1].b_m);
        EXPECT_EQ(bolt.segments[mainCount - 1].b_m, bolt.strike_m);
        EXPECT_DOUBLE_EQ(bolt.strike_m.z, cell.center_m.z);

        for (size_t i = 0; i < bolt.segments.size(); ++i) {
            const BoltSegment& s = bolt.segments[i];
            for (const glm::dvec3& p : {s.a_m, s.b_m}) {
                EXPECT_LE(std::hypot(p.x - cell.center_m.x, p.y - cell.center_m.y),
                          cell.radius_m + 1e-9);
                EXPECT_GE(p.z, cell.center_m.z);
                EXPECT_LE(p.z, cell.cloudBase_m);
            }
            const glm::dvec3 d = s.b_m - s.a_m;
            const double length = glm::length(d);
            const double angle = std::acos(std::clamp(-d.z / length, -1.0, 1.0));
            EXPECT_GE(angle, settings.bolt.branchAngleMin_rad - 1e-9);
            EXPECT_LE(angle, settings.bolt.branchAngleMax_rad + 1e-9);
            EXPECT_LE(length, settings.bolt.branchLengthMax_m + 1e-9);
            // Only the last main segment is shortened (clipped at the surface).
            if (i + 1 != mainCount) {
                EXPECT_GE(length, settings.bolt.branchLengthMin_m - 1e-9);
            }
            if (!s.mainChannel) {
                ++branchSegments;
                EXPECT_LT(s.weight, 1.0f);
                // A branch starts at a node of the tree: the end of an earlier segment.
                bool attached = false;
                for (size_t j = 0; j < i && !attached; ++j)
                    attached = bolt.segments[j].b_m == s.a_m;
                EXPECT_TRUE(attached);
            }
        }
    }
    EXPECT_GT(branchSegments, 0u);
}

TEST(Lightning, DensityIsTheChildProbability) {
    // Density 0: no side branches. Otherwise the fraction of main-channel nodes that start a
    // branch is the density, less the children that would leave the (wide) volume.
    for (double density : {0.0, 0.3, 0.7}) {
        LightningSettings settings = OneCell(30.0, 20000.0);
        settings.cells[0].center_m = {0.0, 0.0, 0.0};
        settings.bolt.density = density;
        const Lightning lightning(settings, 11);
        size_t nodes = 0;
        size_t branchRoots = 0;
        for (const Flash& f : StartingIn(lightning, 0.0, 300.0)) {
            const Bolt bolt = lightning.GrowBolt(f);
            std::vector<glm::dvec3> mainNodes;
            for (const BoltSegment& s : bolt.segments)
                if (s.mainChannel && s.b_m.z > 0.0) mainNodes.push_back(s.b_m);
            nodes += mainNodes.size();
            for (const BoltSegment& s : bolt.segments)
                if (!s.mainChannel &&
                    std::find(mainNodes.begin(), mainNodes.end(), s.a_m) != mainNodes.end())
                    ++branchRoots;
        }
        ASSERT_GT(nodes, 1000u);
        const double fraction = double(branchRoots) / double(nodes);
        // Children below the surface are dropped, which happens only at the lowest node or two
        // of a ~35-node channel: allow 10 %.
        const double sigma = std::sqrt(density * (1.0 - density) / double(nodes));
        EXPECT_LE(fraction, density + 3.0 * sigma) << "density " << density;
        EXPECT_GE(fraction, density * 0.9 - 3.0 * sigma) << "density " << density;
    }
}

TEST(Lightning, StrokeCountsAndIntervalsFollowPublishedStatistics) {
    // Rakov & Uman (2003): 3-5 strokes per flash, geometric-mean interstroke interval 60 ms,
    // flash duration ~0.2-0.3 s. The configured model: 1 + Poisson(mean - 1) strokes and
    // lognormal intervals of geometric mean 60 ms, spread 2.
    LightningSettings settings = OneCell(60.0);
    for (uint64_t seed : {1u, 2u, 3u}) {
        const Lightning lightning(settings, seed);
        const std::vector<Flash> flashes = StartingIn(lightning, 0.0, 36000.0);
        ASSERT_GT(flashes.size(), 30000u);
        double strokes = 0.0;
        double logIntervals = 0.0;
        size_t intervals = 0;
        std::vector<double> durations;
        for (const Flash& f : flashes) {
            ASSERT_GE(f.strokes.size(), 1u);
            ASSERT_LE(f.strokes.size(), size_t(settings.strokes.maxStrokesPerFlash));
            strokes += double(f.strokes.size());
            for (size_t i = 1; i < f.strokes.size(); ++i) {
                const double dt = f.strokes[i].start_s - f.strokes[i - 1].start_s;
                EXPECT_GT(dt, 0.0);
                logIntervals += std::log(dt);
                ++intervals;
            }
            if (f.strokes.size() > 1) durations.push_back(f.strokes.back().start_s - f.start_s);
            EXPECT_EQ(f.start_s, f.strokes.front().start_s);
            EXPECT_GT(f.end_s, f.strokes.back().start_s);
        }
        const double n = double(flashes.size());
        const double meanStrokes = strokes / n;
        EXPECT_NEAR(meanStrokes, settings.strokes.meanStrokesPerFlash,
                    3.0 * std::sqrt((settings.strokes.meanStrokesPerFlash - 1.0) / n));
        EXPECT_GE(meanStrokes, 3.0);  // published range 3-5
        EXPECT_LE(meanStrokes, 5.0);
        const double geometricMean = std::exp(logIntervals / double(intervals));
        const double sigmaLog = std::log(settings.strokes.interStrokeSpread) / std::sqrt(intervals);
        EXPECT_NEAR(std::log(geometricMean), std::log(0.060), 3.0 * sigmaLog);
        std::nth_element(durations.begin(), durations.begin() + durations.size() / 2,
                         durations.end());
        const double medianDuration = durations[durations.size() / 2];
        EXPECT_GE(medianDuration, 0.1);
        EXPECT_LE(medianDuration, 0.3);
    }
}

TEST(Lightning, LightCurvePeaksAtStrokePowerAndIntegratesExactly) {
    const Lightning lightning(OneCell(30.0), 8);
    const std::vector<Flash> flashes = StartingIn(lightning, 0.0, 120.0);
    ASSERT_FALSE(flashes.empty());
    const Flash& f = flashes.front();
    const StrokeSettings& k = lightning.Settings().strokes;
    // Peak of exp(-u/d) - exp(-u/r) at u* = ln(d/r) r d / (d - r).
    const double r = k.pulseRiseTime_s;
    const double d = k.pulseDecayTime_s;
    const double uPeak = std::log(d / r) * r * d / (d - r);
    const ReturnStroke& first = f.strokes.front();
    EXPECT_NEAR(lightning.OpticalPower_W(f, first.start_s + uPeak) / first.peakPower_W, 1.0,
                f.strokes.size() > 1 ? 1e-6 : 1e-12);
    EXPECT_EQ(lightning.OpticalPower_W(f, first.start_s - 1e-3), 0.0);
    EXPECT_NEAR(first.peakPower_W, 3e9, 1.0);

    // The mean over a window equals the trapezoid integral of the instantaneous power.
    const double t0 = first.start_s - 0.001;
    const double t1 = f.end_s;
    double integral = 0.0;
    const int steps = 2000000;
    const double h = (t1 - t0) / steps;
    for (int i = 0; i <= steps; ++i) {
        const double w = (i == 0 || i == steps) ? 0.5 : 1.0;
        integral += w * lightning.OpticalPower_W(f, t0 + i * h);
    }
    integral *= h;
    EXPECT_NEAR(lightning.MeanOpticalPower_W(f, t0, t1) * (t1 - t0) / integral, 1.0, 1e-4);
    // Each stroke radiates peak x (d - r) x the normalisation; the sum is the total energy.
    double energy = 0.0;
    const double scale = 1.0 / (std::exp(-uPeak / d) - std::exp(-uPeak / r));
    for (const ReturnStroke& s : f.strokes) energy += s.peakPower_W * scale * (d - r);
    EXPECT_NEAR(lightning.MeanOpticalPower_W(f, t0, t1 + 10.0) * (t1 + 10.0 - t0) / energy, 1.0,
                1e-9);
    // Intensity is efficacy x power / 4 pi.
    EXPECT_NEAR(
        lightning.MeanLuminousIntensity_cd(f, t0, t1),
        lightning.LuminousEfficacy_lmPerW() * lightning.MeanOpticalPower_W(f, t0, t1) / (4.0 * kPi),
        1e-6);
}

TEST(Lightning, LuminousEfficacyFollowsTheDefinitionOfTheCandela) {
    // A narrow band at 555 nm: 683 lm/W x V(555 nm) = 683 lm/W (V = 1 at the peak; our 10 nm
    // table interpolates to 0.995 there).
    EXPECT_NEAR(PlanckLuminousEfficacy_lmPerW(30000.0, 554.5e-9, 555.5e-9), 683.0, 683.0 * 0.006);
    // Outside the visible: nothing.
    EXPECT_EQ(PlanckLuminousEfficacy_lmPerW(30000.0, 0.9e-6, 1.1e-6), 0.0);
    // A 5800 K blackbody over its whole spectrum: 93 lm/W (published luminous efficacy of an
    // ideal black body at the Sun's temperature).
    EXPECT_NEAR(PlanckLuminousEfficacy_lmPerW(5800.0, 0.1e-6, 50e-6), 93.0, 2.0);
}

TEST(Lightning, ChannelTemperaturePeaksAtThirtyThousandKelvinAndCools) {
    const Lightning lightning(OneCell(30.0), 8);
    const std::vector<Flash> flashes = StartingIn(lightning, 0.0, 120.0);
    ASSERT_FALSE(flashes.empty());
    const Flash& f = flashes.front();
    const double ambient = 290.0;
    EXPECT_EQ(lightning.ChannelTemperature_K(f, f.start_s - 1e-6, ambient), ambient);
    EXPECT_NEAR(lightning.ChannelTemperature_K(f, f.start_s, ambient), 30000.0, 1e-9);
    EXPECT_LT(lightning.ChannelTemperature_K(f, f.start_s + 1e-3, ambient), 10000.0);
    EXPECT_NEAR(lightning.ChannelTemperature_K(f, f.end_s, ambient), ambient, 1.0);
    for (const ReturnStroke& s : f.strokes)
        EXPECT_NEAR(lightning.ChannelTemperature_K(f, s.start_s, ambient), 30000.0, 1e-6);
}

// A straight vertical channel: no branches, zero angles, so the bolt is the segment from the
// root to the surface below it.
LightningSettings StraightChannel() {
    LightningSettings s = OneCell(30.0);
    s.bolt.density = 0.0;
    s.bolt.branchAngleMin_rad = 0.0;
    s.bolt.branchAngleMax_rad = 0.0;
    return s;
}

TEST(Lightning, IlluminanceFallsAsInverseSquareFarAway) {
    const Lightning lightning(StraightChannel(), 21);
    const std::vector<Flash> flashes = StartingIn(lightning, 0.0, 120.0);
    ASSERT_FALSE(flashes.empty());
    const Flash& f = flashes.front();
    const Bolt bolt = lightning.GrowBolt(f);
    const double t0 = f.start_s;
    const double t1 = f.start_s + 1.0 / 30.0;  // one frame
    const glm::dvec3 centre = 0.5 * (f.root_m + bolt.strike_m);
    const double intensity = lightning.MeanLuminousIntensity_cd(f, t0, t1);
    ASSERT_GT(intensity, 0.0);
    for (double d : {20e3, 40e3, 80e3}) {
        const glm::dvec3 p = centre + glm::dvec3(d, 0.0, 0.0);
        const double e = lightning.MeanIlluminance_lux(f, bolt, p, t0, t1, 0.0);
        // Far from a 1.5 km source E d^2 is its intensity (to (L/d)^2 / 12 ~ 5e-4 at 20 km).
        EXPECT_NEAR(e * d * d / intensity, 1.0, 1e-3) << d;
        // Beer-Lambert along the path for a uniform extinction.
        const double beta = 3.912 / 20e3;  // 20 km visibility (Koschmieder)
        EXPECT_NEAR(lightning.MeanIlluminance_lux(f, bolt, p, t0, t1, beta) / e,
                    std::exp(-beta * d), 1e-3);
    }
}

TEST(Lightning, LineSourceIlluminanceMatchesBruteForceSum) {
    // Close to the channel the illuminance is the sum of I dl / r^2 over its length.
    const Lightning lightning(StraightChannel(), 21);
    const std::vector<Flash> flashes = StartingIn(lightning, 0.0, 120.0);
    ASSERT_FALSE(flashes.empty());
    const Flash& f = flashes.front();
    const Bolt bolt = lightning.GrowBolt(f);
    const double t0 = f.start_s;
    const double t1 = f.start_s + 0.01;
    const glm::dvec3 p = bolt.strike_m + glm::dvec3(0.0, 300.0, 200.0);
    double sum = 0.0;
    for (const BoltSegment& s : bolt.segments) {
        const double i = lightning.MeanSegmentIntensity_cdPerM(f, bolt, s, t0, t1);
        const int n = 20000;
        const glm::dvec3 dl = (s.b_m - s.a_m) / double(n);
        for (int j = 0; j < n; ++j) {
            const glm::dvec3 x = s.a_m + (double(j) + 0.5) * dl;
            const glm::dvec3 r = x - p;
            sum += i * glm::length(dl) / glm::dot(r, r);
        }
    }
    EXPECT_NEAR(lightning.MeanIlluminance_lux(f, bolt, p, t0, t1, 0.0) / sum, 1.0, 1e-6);
    // The segment intensities add up to the channel's intensity.
    double total = 0.0;
    for (const BoltSegment& s : bolt.segments)
        total +=
            lightning.MeanSegmentIntensity_cdPerM(f, bolt, s, t0, t1) * glm::length(s.b_m - s.a_m);
    EXPECT_NEAR(total / lightning.MeanLuminousIntensity_cd(f, t0, t1), 1.0, 1e-12);
}

TEST(Lightning, SegmentIntensitiesConserveTheBranchedChannelsLight) {
    // With branches, the first stroke lights the tree and later strokes the main channel; in
    // both cases the segments' intensities sum to the flash's intensity.
    LightningSettings settings = OneCell(30.0);
    settings.bolt.density = 0.7;
    const Lightning lightning(settings, 4);
    for (const Flash& f : StartingIn(lightning, 0.0, 60.0)) {
        const Bolt bolt = lightning.GrowBolt(f);
        for (const auto& [t0, t1] :
             {std::pair{f.start_s, f.start_s + 1e-3}, std::pair{f.start_s, f.end_s}}) {
            double total = 0.0;
            for (const BoltSegment& s : bolt.segments)
                total += lightning.MeanSegmentIntensity_cdPerM(f, bolt, s, t0, t1) *
                         glm::length(s.b_m - s.a_m);
            EXPECT_NEAR(total / lightning.MeanLuminousIntensity_cd(f, t0, t1), 1.0, 1e-9);
        }
    }
}

TEST(Lightning, SceneIlluminanceSumsTheFlashesOfTheFrame) {
    const Lightning lightning(OneCell(60.0), 17);
    const glm::dvec3 p(0.0, 0.0, 10.0);
    const std::vector<Flash> flashes = StartingIn(lightning, 0.0, 30.0);
    ASSERT_FALSE(flashes.empty());
    const double t0 = flashes.front().start_s;
    const double t1 = t0 + 1.0 / 60.0;
    double sum = 0.0;
    for (const Flash& f : lightning.FlashesBetween(t0, t1))
        sum += lightning.MeanIlluminance_lux(f, lightning.GrowBolt(f), p, t0, t1, 1e-4);
    EXPECT_GT(sum, 0.0);
    EXPECT_EQ(lightning.SceneIlluminance_lux(p, t0, t1, 1e-4), sum);
    // Between flashes the scene is dark.
    const double quiet = flashes.front().start_s - 1e-3;
    if (lightning.ActiveFlashes(quiet).empty()) {
        EXPECT_EQ(lightning.SceneIlluminance_lux(p, quiet, quiet, 0.0), 0.0);
    }
}

TEST(Lightning, RejectsInconsistentSettings) {
    LightningSettings s = OneCell(1.0);
    s.bolt.branchAngleMin_rad = 50.0 * kDeg;
    EXPECT_THROW(Lightning(s, 1), InputError);
    s = OneCell(1.0, 50.0);  // radius below the 100 m branch length
    EXPECT_THROW(Lightning(s, 1), InputError);
    s = OneCell(1.0);
    s.cells[0].cloudBase_m = -10.0;
    EXPECT_THROW(Lightning(s, 1), InputError);
    s = OneCell(1.0);
    s.bolt.density = 1.5;
    EXPECT_THROW(Lightning(s, 1), InputError);
    const Lightning ok(OneCell(1.0), 1);
    EXPECT_THROW(ok.FlashesBetween(2.0, 1.0), InputError);
    EXPECT_THROW(ok.FlashesBetween(0.0, std::nan("")), InputError);
    EXPECT_THROW(ok.FlashesBetween(0.0, 2e6), InputError);  // a window over 1e6 s
    EXPECT_THROW(ok.FlashesBetween(1e300, 1e300), InputError);
}

// Parses `text` and reads its `lightning` mapping; returns the ConfigError message or "".
std::string ReadError(const std::string& text, LightningSettings* out = nullptr) {
    try {
        ConfigDocument doc = ParseConfigText(text, "storm.yaml");
        ReadMap(doc.root, [&](ConfigMap& root) {
            LightningSettings s = ReadLightningSettings(root.Require("lightning", "a mapping"));
            if (out) *out = s;
        });
    } catch (const ConfigError& e) {
        return e.what();
    }
    return "";
}

TEST(LightningConfig, ReadsSettingsInFileUnits) {
    const std::string text =
        "lightning:\n"
        "  branch_angle_min_deg: 5\n"
        "  branch_angle_max_deg: 30\n"
        "  branch_length_max_m: 60\n"
        "  branch_density: 0.25\n"
        "  strokes_mean: 4\n"
        "  peak_optical_power_W: 5e9\n"
        "  cells:\n"
        "    - center_m: [1000, -2000, 0]\n"
        "      radius_m: 4000\n"
        "      cloud_base_m: 1200\n"
        "      flash_rate_per_min: 3\n";
    LightningSettings s;
    ASSERT_EQ(ReadError(text, &s), "");
    EXPECT_NEAR(s.bolt.branchAngleMin_rad, 5.0 * kDeg, 1e-15);
    EXPECT_NEAR(s.bolt.branchAngleMax_rad, 30.0 * kDeg, 1e-15);
    EXPECT_EQ(s.bolt.branchLengthMax_m, 60.0);
    EXPECT_EQ(s.bolt.density, 0.25);
    EXPECT_EQ(s.strokes.meanStrokesPerFlash, 4.0);
    EXPECT_EQ(s.strokes.firstStrokePeakPower_W, 5e9);
    ASSERT_EQ(s.cells.size(), 1u);
    EXPECT_EQ(s.cells[0].center_m, glm::dvec3(1000.0, -2000.0, 0.0));
    EXPECT_EQ(s.cells[0].radius_m, 4000.0);
    EXPECT_EQ(s.cells[0].cloudBase_m, 1200.0);
    EXPECT_EQ(s.cells[0].flashRate_perMin, 3.0);
}

TEST(LightningConfig, ErrorsNameTheKeyPath) {
    const std::string cell =
        "  cells:\n"
        "    - center_m: [0, 0, 0]\n"
        "      radius_m: 4000\n"
        "      cloud_base_m: 1200\n"
        "      flash_rate_per_min: 3\n";
    std::string e = ReadError("lightning:\n  branch_density: 1.5\n" + cell);
    EXPECT_NE(e.find("lightning.branch_density"), std::string::npos) << e;
    e = ReadError("lightning:\n  branch_angle_min_deg: 50\n" + cell);
    EXPECT_NE(e.find("branch_angle_m"), std::string::npos) << e;
    e = ReadError("lightning:\n  branch_lenght_max_m: 50\n" + cell);  // misspelt key
    EXPECT_NE(e.find("branch_lenght_max_m"), std::string::npos) << e;
    e = ReadError("lightning:\n  strokes_mean: 3\n");
    EXPECT_NE(e.find("lightning.cells"), std::string::npos) << e;
    std::string bad = cell;
    bad.replace(bad.find("radius_m: 4000"), 14, "radius_m: 40");
    e = ReadError("lightning:\n" + bad);
    EXPECT_NE(e.find("lightning.cells[0].radius_m"), std::string::npos) << e;
    bad = cell;
    bad.replace(bad.find("cloud_base_m: 1200"), 18, "cloud_base_m: -5");
    e = ReadError("lightning:\n" + bad);
    EXPECT_NE(e.find("lightning.cells[0].cloud_base_m"), std::string::npos) << e;
    bad = cell;
    bad.replace(bad.find("flash_rate_per_min: 3"), 21, "flash_rate_per_min: fast");
    e = ReadError("lightning:\n" + bad);
    EXPECT_NE(e.find("lightning.cells[0].flash_rate_per_min"), std::string::npos) << e;
}

}  // namespace
}  // namespace seasense::scene
