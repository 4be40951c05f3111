// Reading thermal imager settings from YAML: SI conversion, defaults, errors with key paths.
#include "sensors/thermal/thermal_settings.h"

#include <gtest/gtest.h>

#include <string>

namespace seasense::sensors {
namespace {

ThermalImagerSettings Read(const std::string& text) {
    scene::ConfigDocument doc = scene::ParseConfigText(text, "imager.yaml");
    scene::ConfigMap root(doc.root);
    ThermalImagerSettings s = ReadThermalImagerSettings(root.Require("imager", "a mapping"));
    root.Finish();
    return s;
}

std::string ErrorOf(const std::string& text) {
    try {
        Read(text);
    } catch (const scene::ConfigError& e) {
        return e.what();
    }
    ADD_FAILURE() << "no ConfigError for:\n" << text;
    return "";
}

TEST(ThermalSettings, ReadsEveryKeyInSiUnits) {
    const ThermalImagerSettings s = Read(
        "imager:\n"
        "  optics: {focal_length_mm: 50, f_number: 2, transmission: 0.8,"
        " aberration_sigma_px: 0.5, psf_radius_px: 5}\n"
        "  detector: {pitch_um: 15, fill_factor: 0.8, time_constant_ms: 0}\n"
        "  noise: {netd_mK: 20, reference_K: 293.15, offset_fpn_K: 0.2, gain_fpn: 0.01,"
        " row_fpn_K: 0.05, column_fpn_K: 0.04}\n"
        "  nuc: {low_K: 280, high_K: 320, frames: 8}\n"
        "  adc: {min_K: 250, max_K: 400}\n"
        "  agc: {mode: linear, plateau: 50, clip_low_percent: 0.5, clip_high_percent: 2,"
        " time_constant_s: 1, gain: 2, level_counts: 4000}\n"
        "  display: {polarity: black_hot, palette: ironbow}\n");
    EXPECT_DOUBLE_EQ(s.focalLength_m, 0.050);
    EXPECT_DOUBLE_EQ(s.fNumber, 2.0);
    EXPECT_DOUBLE_EQ(s.opticsTransmission, 0.8);
    EXPECT_DOUBLE_EQ(s.aberrationSigma_m, 0.5 * 15e-6);  // pixels of the configured pitch
    EXPECT_EQ(s.psfRadius_px, 5);
    EXPECT_DOUBLE_EQ(s.pitch_m, 15e-6);
    EXPECT_DOUBLE_EQ(s.fillFactor, 0.8);
    EXPECT_DOUBLE_EQ(s.timeConstant_s, 0.0);
    EXPECT_DOUBLE_EQ(s.netd_K, 0.020);
    EXPECT_DOUBLE_EQ(s.netdReference_K, 293.15);
    EXPECT_DOUBLE_EQ(s.offsetFpn_K, 0.2);
    EXPECT_DOUBLE_EQ(s.gainFpn, 0.01);
    EXPECT_DOUBLE_EQ(s.rowFpn_K, 0.05);
    EXPECT_DOUBLE_EQ(s.columnFpn_K, 0.04);
    EXPECT_TRUE(s.nuc);
    EXPECT_DOUBLE_EQ(s.nucLow_K, 280.0);
    EXPECT_DOUBLE_EQ(s.nucHigh_K, 320.0);
    EXPECT_EQ(s.nucFrames, 8);
    EXPECT_DOUBLE_EQ(s.adcMin_K, 250.0);
    EXPECT_DOUBLE_EQ(s.adcMax_K, 400.0);
    EXPECT_EQ(s.agc.mode, AgcMode::LinearMinMax);
    EXPECT_DOUBLE_EQ(s.agc.plateau, 50.0);
    EXPECT_DOUBLE_EQ(s.agc.clipLow, 0.005);
    EXPECT_DOUBLE_EQ(s.agc.clipHigh, 0.02);
    EXPECT_DOUBLE_EQ(s.agc.timeConstant_s, 1.0);
    EXPECT_DOUBLE_EQ(s.agc.manualGain, 2.0);
    EXPECT_DOUBLE_EQ(s.agc.manualLevel_counts, 4000.0);
    EXPECT_EQ(s.agc.polarity, Polarity::BlackHot);
    EXPECT_EQ(s.agc.palette, Palette::Ironbow);
}

TEST(ThermalSettings, EmptyMappingKeepsTheDefaults) {
    const ThermalImagerSettings s = Read("imager: {}\n");
    const ThermalImagerSettings d;
    EXPECT_EQ(s.focalLength_m, d.focalLength_m);
    EXPECT_EQ(s.netd_K, d.netd_K);
    EXPECT_EQ(s.timeConstant_s, d.timeConstant_s);
    EXPECT_FALSE(s.nuc);
    EXPECT_EQ(s.agc.mode, AgcMode::PlateauEqualization);
}

TEST(ThermalSettings, ErrorsNameTheKeyPath) {
    struct Case {
        const char* text;
        const char* expected;  // must appear in the message
    };
    const Case cases[] = {
        {"imager:\n  optics: {focal_lenght_mm: 25}\n", "imager.optics.focal_lenght_mm"},
        {"imager:\n  detector: {fill_factor: 1.5}\n",
         "imager.detector.fill_factor: expected a number in (0, 1], found 1.5"},
        {"imager:\n  optics: {aberration_sigma_um: 3, aberration_sigma_px: 0.2}\n",
         "imager.optics.aberration_sigma_px: expected only one of"},
        {"imager:\n  adc: {min_K: 300, max_K: 280}\n",
         "imager.adc.max_K: expected a number (K) above min_K = 300, found 280"},
        {"imager:\n  adc: {min_K: 350}\n", "imager.adc.min_K: expected a number (K) below max_K"},
        {"imager:\n  nuc: {low_K: 320, high_K: 300}\n", "imager.nuc.high_K"},
        {"imager:\n  agc: {mode: auto}\n", "imager.agc.mode"},
        {"imager:\n  display: {palette: viridis}\n", "imager.display.palette"},
        {"imager:\n  noise: {netd_mK: -5}\n", "imager.noise.netd_mK"},
        {"imager:\n  lens: {}\n", "imager.lens"},
    };
    for (const Case& c : cases) {
        const std::string message = ErrorOf(c.text);
        EXPECT_NE(message.find(c.expected), std::string::npos) << message;
        EXPECT_EQ(message.rfind("imager.yaml:", 0), 0u) << message;
    }
}

}  // namespace
}  // namespace seasense::sensors
