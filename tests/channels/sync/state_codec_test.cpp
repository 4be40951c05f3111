// Frame-state encoding: a decoded state equals the encoded one bit for bit; damage is refused.
#include "channels/sync/state_codec.h"

#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "scene/core/error.h"
#include "scene/core/rng.h"

namespace seasense::channels::sync {
namespace {

scene::FrameState Sample(size_t entities) {
    scene::FrameState s;
    s.frame = 123456789012;
    s.time_s = 1.0 / 3.0;
    s.utc.unixNs = 1781234567891234567;
    s.sun.direction = {0.1, -0.2, 0.97467943448089633};
    s.sun.elevation_rad = -0.0123;
    s.sun.azimuth_rad = 5.1;
    s.sun.illuminance_lux = 1234.5678;
    s.moon.direction = {-0.3, 0.5, 0.81240384046359604};
    s.moon.elevation_rad = 0.9484;
    s.moon.azimuth_rad = 2.7;
    s.moon.illuminance_lux = 0.2345;
    s.moon.phaseAngle_rad = 0.321;
    s.moon.distance_m = 3.7e8;
    s.eyepoint.position_m = {1e-300, -0.0, 2.0};
    s.eyepoint.worldFromBody = glm::dmat3(0.6, 0.8, 0, -0.8, 0.6, 0, 0, 0, 1);
    for (size_t i = 0; i < entities; ++i) {
        scene::Pose p;
        p.position_m = {double(i) * 3.7, -1.0 / double(i + 1), 1e9};
        p.worldFromBody[2][0] = 1e-17 * double(i);
        s.entityPoses.push_back(p);
    }
    return s;
}

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(StateCodec, RoundTripIsBitExact) {
    for (size_t entities : {0u, 1u, 7u}) {
        const scene::FrameState s = Sample(entities);
        std::vector<uint8_t> buf(EncodedFrameStateBytes(entities));
        ASSERT_EQ(EncodeFrameState(s, buf.data(), buf.size()), buf.size());
        const scene::FrameState d = DecodeFrameState(buf.data(), buf.size());
        EXPECT_EQ(d.frame, s.frame);
        EXPECT_EQ(d.utc, s.utc);
        EXPECT_TRUE(SameBits(d.time_s, s.time_s));
        for (int k = 0; k < 3; ++k) EXPECT_TRUE(SameBits(d.sun.direction[k], s.sun.direction[k]));
        EXPECT_TRUE(SameBits(d.sun.illuminance_lux, s.sun.illuminance_lux));
        EXPECT_TRUE(SameBits(d.sun.elevation_rad, s.sun.elevation_rad));
        for (int k = 0; k < 3; ++k) EXPECT_TRUE(SameBits(d.moon.direction[k], s.moon.direction[k]));
        EXPECT_TRUE(SameBits(d.moon.elevation_rad, s.moon.elevation_rad));
        EXPECT_TRUE(SameBits(d.moon.azimuth_rad, s.moon.azimuth_rad));
        EXPECT_TRUE(SameBits(d.moon.illuminance_lux, s.moon.illuminance_lux));
        EXPECT_TRUE(SameBits(d.moon.phaseAngle_rad, s.moon.phaseAngle_rad));
        EXPECT_TRUE(SameBits(d.moon.distance_m, s.moon.distance_m));
        EXPECT_TRUE(SameBits(d.eyepoint.position_m.y, s.eyepoint.position_m.y));  // −0.0 kept
        EXPECT_EQ(d.eyepoint.worldFromBody, s.eyepoint.worldFromBody);
        ASSERT_EQ(d.entityPoses.size(), entities);
        for (size_t i = 0; i < entities; ++i) {
            EXPECT_EQ(d.entityPoses[i].position_m, s.entityPoses[i].position_m);
            EXPECT_EQ(d.entityPoses[i].worldFromBody, s.entityPoses[i].worldFromBody);
        }
    }
}

TEST(StateCodec, RefusesSmallSlotsAndDamagedStates) {
    const scene::FrameState s = Sample(3);
    std::vector<uint8_t> buf(EncodedFrameStateBytes(3));
    EXPECT_THROW(EncodeFrameState(s, buf.data(), buf.size() - 1), RuntimeError);
    EncodeFrameState(s, buf.data(), buf.size());
    EXPECT_THROW(DecodeFrameState(buf.data(), buf.size() - 8), RuntimeError);
    std::vector<uint8_t> badTag = buf;
    badTag[0] ^= 0xFF;
    EXPECT_THROW(DecodeFrameState(badTag.data(), badTag.size()), RuntimeError);
    std::vector<uint8_t> badCount = buf;
    badCount[4] = 9;  // claims 9 entities
    EXPECT_THROW(DecodeFrameState(badCount.data(), badCount.size()), RuntimeError);
}

// A state slot carries the state and the host's sea fields: the state comes back bit for bit and
// the fields as the same bytes (the codec does not read them), a slot without fields has none,
// and a slot too small for them or cut inside the state is refused.
TEST(StateCodec, SlotCarriesTheStateAndTheSeaFields) {
    const scene::FrameState s = Sample(2);
    std::vector<uint8_t> fields(100003);
    for (size_t i = 0; i < fields.size(); ++i) fields[i] = uint8_t(scene::Mix64(i) >> 56);
    std::vector<uint8_t> slot(StateSlotBytes(2, fields.size()));
    ASSERT_EQ(EncodeStateSlot(s, fields, slot.data(), slot.size()), slot.size());
    const StateSlotContents c = DecodeStateSlot(slot.data(), slot.size());
    EXPECT_EQ(c.state.frame, s.frame);
    EXPECT_EQ(c.state.entityPoses.size(), 2u);
    EXPECT_EQ(c.state.eyepoint.worldFromBody, s.eyepoint.worldFromBody);
    ASSERT_EQ(c.sea.size(), fields.size());
    EXPECT_EQ(std::memcmp(c.sea.data(), fields.data(), fields.size()), 0);

    const size_t n = EncodeStateSlot(s, {}, slot.data(), slot.size());
    EXPECT_EQ(n, EncodedFrameStateBytes(2));
    EXPECT_TRUE(DecodeStateSlot(slot.data(), n).sea.empty());

    EXPECT_THROW(EncodeStateSlot(s, fields, slot.data(), slot.size() - 1), RuntimeError);
    EXPECT_THROW(DecodeStateSlot(slot.data(), EncodedFrameStateBytes(2) - 1), RuntimeError);
}

}  // namespace
}  // namespace seasense::channels::sync
