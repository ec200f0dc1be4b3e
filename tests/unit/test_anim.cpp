// Animation at time T (SPEC section 12): the interpolators' functions, the TimeSensor's cycles,
// and ROUTE cascades on real node trees. Expected values are worked out by hand in the comments.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "anim/animator.h"
#include "anim/interpolate.h"
#include "anim/time_sensor.h"
#include "parser/load.h"

namespace vr {
namespace {

constexpr double kPiD = 3.14159265358979323846;

std::vector<double> at(std::vector<double> key, std::vector<double> value, size_t width,
                       Blend blend, double f) {
    return interpolate(key, value, width, blend, f);
}

// Binary fractions: these blends are exact in double precision, so the checks are exact.
TEST(Interpolate, ScalarAtKeysBetweenAndOutside) {
    const std::vector<double> k{0.0, 0.5, 1.0}, v{1.0, 3.0, 2.0};
    EXPECT_EQ(at(k, v, 1, Blend::Linear, -1.0), std::vector<double>{1.0});  // before: first
    EXPECT_EQ(at(k, v, 1, Blend::Linear, 0.0), std::vector<double>{1.0});
    EXPECT_EQ(at(k, v, 1, Blend::Linear, 0.25), std::vector<double>{2.0});  // 1 + 0.5 * 2
    EXPECT_EQ(at(k, v, 1, Blend::Linear, 0.5), std::vector<double>{3.0});
    EXPECT_EQ(at(k, v, 1, Blend::Linear, 0.75), std::vector<double>{2.5});  // 3 - 0.5 * 1
    EXPECT_EQ(at(k, v, 1, Blend::Linear, 1.0), std::vector<double>{2.0});
    EXPECT_EQ(at(k, v, 1, Blend::Linear, 7.0), std::vector<double>{2.0});  // after: last
    EXPECT_TRUE(at({}, {}, 1, Blend::Linear, 0.5).empty());  // no keys: no event (X3D 19.2.2)
    EXPECT_TRUE(at(k, {1.0, 2.0}, 1, Blend::Linear, 0.5).empty());  // fewer values than keys
}

TEST(Interpolate, PositionAndCoordinateBlendEachComponent) {
    EXPECT_EQ(at({0, 1}, {0, 0, 0, 2, 4, -8}, 3, Blend::Linear, 0.25),
              (std::vector<double>{0.5, 1.0, -2.0}));
    // Two points a key (CoordinateInterpolator): 6 numbers a key.
    EXPECT_EQ(at({0, 2}, {0, 0, 0, 1, 1, 1, 4, 0, 0, 1, 1, 5}, 6, Blend::Linear, 0.5),
              (std::vector<double>{1, 0, 0, 1, 1, 2}));
    // PositionInterpolator2D: 2 numbers.
    EXPECT_EQ(at({0, 1}, {1, 1, 3, -1}, 2, Blend::Linear, 0.5), (std::vector<double>{2, 0}));
}

TEST(Interpolate, EqualKeysJumpAtTheKey) {
    // key [0 .5 .5 1]: up to 0.5 the first segment, from 0.5 on the third.
    const std::vector<double> k{0.0, 0.5, 0.5, 1.0}, v{0.0, 1.0, 5.0, 6.0};
    EXPECT_EQ(at(k, v, 1, Blend::Linear, 0.5)[0], 5.0);
    EXPECT_EQ(at(k, v, 1, Blend::Linear, 0.25)[0], 0.5);
    EXPECT_EQ(at(k, v, 1, Blend::Linear, 0.75)[0], 5.5);
}

TEST(Interpolate, OrientationTakesTheShortestArc) {
    // About +Y from 0 to pi/2: half way is pi/4 about +Y. Tolerance: sin/cos/atan2 each round
    // once, a few ulps of pi/4.
    const std::vector<double> r =
        at({0, 1}, {0, 1, 0, 0, 0, 1, 0, kPiD / 2}, 4, Blend::Rotation, 0.5);
    EXPECT_NEAR(r[0], 0.0, 1e-15);
    EXPECT_NEAR(r[1], 1.0, 1e-15);
    EXPECT_NEAR(r[3], kPiD / 4, 1e-15);
    // 0.1 rad to 6.0 rad about +Z: 6.0 is -0.28319 rad, so the short way passes through 0 and the
    // midpoint is (0.1 - 0.28319) / 2 = -0.091593 rad about +Z (not (0.1 + 6) / 2 = 3.05).
    const std::vector<double> s = at({0, 1}, {0, 0, 1, 0.1, 0, 0, 1, 6.0}, 4, Blend::Rotation, 0.5);
    EXPECT_NEAR(s[2] * s[3], (0.1 + (6.0 - 2 * kPiD)) / 2, 1e-14);
    // An axis that is not unit length is normalised (SPEC section 2): same as above.
    const std::vector<double> u =
        at({0, 1}, {0, 3, 0, 0, 0, 2, 0, kPiD / 2}, 4, Blend::Rotation, 0.5);
    EXPECT_NEAR(u[1], 1.0, 1e-15);
    EXPECT_NEAR(u[3], kPiD / 4, 1e-15);
}

TEST(Interpolate, ColorBlendsInHsv) {
    // Red to green: hue 0 -> 1/3, half way is hue 1/6, yellow (RGB blending would give 0.5 0.5 0).
    // Tolerance: the hue 1/3 = 2/6 rounds once, which moves 6h off 1 by an ulp.
    std::vector<double> c = at({0, 1}, {1, 0, 0, 0, 1, 0}, 3, Blend::Hsv, 0.5);
    EXPECT_NEAR(c[0], 1.0, 1e-15);
    EXPECT_NEAR(c[1], 1.0, 1e-15);
    EXPECT_NEAR(c[2], 0.0, 1e-15);
    // Blue (hue 2/3) to red (hue 0): the short way is through magenta (hue 5/6) = 1 0 1.
    c = at({0, 1}, {0, 0, 1, 1, 0, 0}, 3, Blend::Hsv, 0.5);
    EXPECT_NEAR(c[0], 1.0, 1e-15);
    EXPECT_NEAR(c[1], 0.0, 1e-15);
    EXPECT_NEAR(c[2], 1.0, 1e-15);
    // Red to grey 0.5: the grey takes red's hue; S 1 -> 0 gives 0.5, V 1 -> 0.5 gives 0.75, so
    // RGB = (V, V (1 - S), V (1 - S)) = 0.75 0.375 0.375 (exact binary fractions).
    c = at({0, 1}, {1, 0, 0, 0.5, 0.5, 0.5}, 3, Blend::Hsv, 0.5);
    EXPECT_EQ(c, (std::vector<double>{0.75, 0.375, 0.375}));
}

TEST(Interpolate, NormalsStayUnitLength) {
    // +X to +Y at 0.5: the bisector (1 1 0) / sqrt 2, unit length (a linear blend has 0.71).
    const std::vector<double> n = at({0, 1}, {1, 0, 0, 0, 1, 0}, 3, Blend::UnitVector, 0.5);
    EXPECT_NEAR(n[0], std::sqrt(0.5), 1e-15);
    EXPECT_NEAR(n[1], std::sqrt(0.5), 1e-15);
    EXPECT_NEAR(n[2], 0.0, 1e-15);
    // A quarter of the way: 22.5 degrees from +X.
    const std::vector<double> q = at({0, 1}, {1, 0, 0, 0, 1, 0}, 3, Blend::UnitVector, 0.25);
    EXPECT_NEAR(q[0], std::cos(kPiD / 8), 1e-15);
    EXPECT_NEAR(q[1], std::sin(kPiD / 8), 1e-15);
}

TimeSensorState sensor(double cycle, bool loop, double start, double stop, double now,
                       bool enabled = true) {
    TimeSensorFields f;
    f.cycle_interval = cycle;
    f.loop = loop;
    f.start_time = start;
    f.stop_time = stop;
    f.enabled = enabled;
    return time_sensor_at(f, now);
}

TEST(TimeSensor, OneCycleWithoutLoop) {
    EXPECT_FALSE(sensor(2, false, 0, 0, -1).sent);  // before startTime: nothing yet
    TimeSensorState s = sensor(2, false, 0, 0, 0);
    EXPECT_TRUE(s.sent && s.active);
    EXPECT_EQ(s.fraction, 0.0);  // at startTime: the first key
    EXPECT_EQ(sensor(2, false, 0, 0, 1).fraction, 0.5);
    s = sensor(2, false, 0, 0, 2);  // the cycle ends: inactive, holding fraction 1
    EXPECT_FALSE(s.active);
    EXPECT_EQ(s.fraction, 1.0);
    EXPECT_EQ(sensor(2, false, 0, 0, 50).fraction, 1.0);
    EXPECT_EQ(sensor(2, false, 0, 0, 50).time, 2.0);  // when it stopped
}

TEST(TimeSensor, LoopCyclesAndEndsOfCycles) {
    EXPECT_EQ(sensor(2, true, 0, 0, 3).fraction, 0.5);
    EXPECT_EQ(sensor(2, true, 0, 0, 4).fraction, 1.0);  // f = 0 after the start reads 1
    EXPECT_EQ(sensor(2, true, 0, 0, 4).cycle_time, 2.0);
    EXPECT_EQ(sensor(2, true, 0, 0, 4.5).fraction, 0.25);
    EXPECT_EQ(sensor(2, true, 0, 0, 4.5).cycle_time, 4.0);
    EXPECT_TRUE(sensor(2, true, 0, 0, 1e6).active);
}

TEST(TimeSensor, StopTimeBeforeStartIsIgnoredAfterItStops) {
    // stopTime 0.5 <= startTime 1: ignored, the loop runs on: at 10, (9 mod 2) / 2 = 0.5.
    EXPECT_FALSE(sensor(2, true, 1, 0.5, 0.5).sent);
    TimeSensorState s = sensor(2, true, 1, 0.5, 10);
    EXPECT_TRUE(s.active);
    EXPECT_EQ(s.fraction, 0.5);
    // stopTime 3 > startTime 0: stops at 3 with the fraction of that moment, (3 mod 2) / 2.
    s = sensor(2, true, 0, 3, 5);
    EXPECT_FALSE(s.active);
    EXPECT_EQ(s.fraction, 0.5);
    EXPECT_EQ(s.time, 3.0);
}

TEST(TimeSensor, DisabledOrZeroCycleSendsNothing) {
    EXPECT_FALSE(sensor(2, true, 0, 0, 1, false).sent);
    EXPECT_FALSE(sensor(0, true, 0, 0, 1).sent);
}

// ---- ROUTEs on node trees -----------------------------------------------------------------------

struct World {
    LoadedScene loaded;
    Diagnostics diagnostics;
    std::unique_ptr<Animator> animator;

    explicit World(const std::string& body, const std::string& header = "#VRML V2.0 utf8\n") {
        loaded = load_scene_text(header + body, "anim.wrl");
        EXPECT_TRUE(loaded.ok()) << loaded.diagnostics.format(loaded.sources);
        animator = std::make_unique<Animator>(loaded.tree, diagnostics);
    }
    // The nth node (in reading order) a DEF named: PROTO bodies repeat their names per instance.
    NodeId def(std::string_view name, int nth = 0) const {
        for (NodeId i = 0; i < loaded.tree.nodes.size(); ++i)
            if (loaded.tree.def_name(i) == name && nth-- == 0) return i;
        ADD_FAILURE() << "no DEF " << name;
        return 0;
    }
    std::vector<double> field(std::string_view node, std::string_view field, int nth = 0) const {
        const FieldView v = loaded.tree.get(def(node, nth), field);
        return {v.numbers.begin(), v.numbers.end()};
    }
    std::string messages() const { return diagnostics.format(loaded.sources); }
};

TEST(Routes, ChainOfThreeCarriesTheValue) {
    // Sensor -> interpolator -> T1.translation -> (translation_changed) T2.translation.
    World w(R"(
DEF Clock TimeSensor { loop TRUE cycleInterval 4 }
DEF Mover PositionInterpolator { key [0 1] keyValue [0 0 0, 8 4 0] }
DEF T1 Transform {}
DEF T2 Transform { translation 9 9 9 }
ROUTE Clock.fraction_changed TO Mover.set_fraction
ROUTE Mover.value_changed TO T1.set_translation
ROUTE T1.translation_changed TO T2.set_translation
)");
    EXPECT_TRUE(w.animator->animated());
    EXPECT_TRUE(w.animator->evaluate(1.0));  // fraction 1/4: (2 1 0)
    EXPECT_EQ(w.field("T1", "translation"), (std::vector<double>{2, 1, 0}));
    EXPECT_EQ(w.field("T2", "translation"), (std::vector<double>{2, 1, 0}));
    EXPECT_FALSE(w.animator->evaluate(1.0));  // the same time again: nothing changed
    EXPECT_TRUE(w.animator->evaluate(0.0));   // T = 0: the first key value
    EXPECT_EQ(w.field("T2", "translation"), (std::vector<double>{0, 0, 0}));
    EXPECT_TRUE(w.messages().empty()) << w.messages();
}

TEST(Routes, BeforeTheSensorStartsFieldsKeepTheirFileValues) {
    World w(R"(
DEF Clock TimeSensor { startTime 5 }
DEF S ScalarInterpolator { key [0 1] keyValue [0.25 0.75] }
DEF M Material { transparency 0.5 }
ROUTE Clock.fraction_changed TO S.set_fraction
ROUTE S.value_changed TO M.set_transparency
)");
    w.animator->evaluate(5.5);
    EXPECT_EQ(w.field("M", "transparency"), std::vector<double>{0.5});  // 0.25 + 0.5 * 0.5
    w.animator->evaluate(1.0);  // before startTime: the file value is back
    EXPECT_EQ(w.field("M", "transparency"), std::vector<double>{0.5});
    w.animator->evaluate(5.25);
    EXPECT_EQ(w.field("M", "transparency"), std::vector<double>{0.375});
    w.animator->evaluate(1.0);
    EXPECT_EQ(w.field("M", "transparency"), std::vector<double>{0.5});
}

TEST(Routes, FanOutAndFanInInRouteOrder) {
    World w(R"(
DEF Clock TimeSensor { loop TRUE }
DEF A PositionInterpolator { key [0 1] keyValue [0 0 0, 4 0 0] }
DEF B PositionInterpolator { key [0 1] keyValue [0 0 0, 0 8 0] }
DEF T Transform {}
DEF U Transform {}
ROUTE Clock.fraction_changed TO A.set_fraction
ROUTE Clock.fraction_changed TO B.set_fraction
ROUTE A.value_changed TO U.translation
ROUTE A.value_changed TO T.set_translation
ROUTE B.value_changed TO T.set_translation
)");
    w.animator->evaluate(0.5);
    EXPECT_EQ(w.field("U", "translation"), (std::vector<double>{2, 0, 0}));
    EXPECT_EQ(w.field("T", "translation"), (std::vector<double>{0, 4, 0}));  // B's ROUTE is last
}

TEST(Routes, LoopsEndAfterOneEventPerRoute) {
    World w(R"(
DEF Clock TimeSensor { loop TRUE }
DEF P PositionInterpolator { key [0 1] keyValue [0 0 0, 1 1 1] }
DEF T1 Transform {}
DEF T2 Transform {}
ROUTE Clock.fraction_changed TO P.set_fraction
ROUTE P.value_changed TO T1.set_translation
ROUTE T1.translation_changed TO T2.set_translation
ROUTE T2.translation_changed TO T1.set_translation
)");
    w.animator->evaluate(0.5);
    EXPECT_EQ(w.field("T1", "translation"), (std::vector<double>{0.5, 0.5, 0.5}));
    EXPECT_EQ(w.field("T2", "translation"), (std::vector<double>{0.5, 0.5, 0.5}));
}

TEST(Routes, MismatchedTypesAreAnErrorAtTheRoute) {
    World w(R"(DEF Clock TimeSensor {}
DEF T Transform {}
  ROUTE Clock.fraction_changed TO T.set_translation
)");
    ASSERT_TRUE(w.diagnostics.has_errors());
    const std::string text = w.messages();
    EXPECT_NE(text.find("anim.wrl:4:3: error: ROUTE from TimeSensor 'Clock'.fraction_changed "
                        "(SFFloat) to Transform 'T'.set_translation (SFVec3f)"),
              std::string::npos)
        << text;
}

TEST(Routes, UnknownEventsAndScriptsWarn) {
    World w(R"(DEF Clock TimeSensor {}
DEF T Transform {}
DEF S Script { eventOut SFVec3f pos }
ROUTE Clock.fraction_changed TO T.set_nothing
ROUTE S.pos TO T.set_translation
ROUTE S.pos TO T.set_center
)");
    EXPECT_FALSE(w.diagnostics.has_errors());
    const std::string text = w.messages();
    EXPECT_NE(text.find("Transform 'T' has no input event 'set_nothing'"), std::string::npos);
    // Once per Script, however many of its outputs are routed.
    EXPECT_NE(text.find("Script 'S' is not run"), std::string::npos) << text;
    EXPECT_EQ(text.find("(2 times)"), std::string::npos) << text;
}

TEST(Routes, ProtoBodyRoutesAndIsEvents) {
    // The instance's set_f reaches the body's interpolator through IS; the body's own ROUTE moves
    // its Transform. Two instances: each body's ROUTE connects its own nodes.
    World w(R"(
PROTO Mover [ eventIn SFFloat set_f  field SFVec3f far 1 0 0 ] {
  DEF Body Transform { children Shape { geometry Box {} } }
  DEF Interp PositionInterpolator { set_fraction IS set_f key [0 1] keyValue [0 0 0, 1 0 0] }
  ROUTE Interp.value_changed TO Body.set_translation
}
DEF M1 Mover {}
DEF M2 Mover {}
DEF Clock TimeSensor { loop TRUE cycleInterval 2 }
ROUTE Clock.fraction_changed TO M1.set_f
)");
    EXPECT_TRUE(w.messages().empty()) << w.messages();
    w.animator->evaluate(0.5);  // fraction 0.25
    // The instances' Transforms, M1's first: a DEF on an instance names its body's first node
    // only when that node has no DEF of its own.
    EXPECT_EQ(w.field("Body", "translation", 0), (std::vector<double>{0.25, 0, 0}));
    EXPECT_EQ(w.field("Body", "translation", 1), (std::vector<double>{0, 0, 0}));  // not routed
}

TEST(Routes, SetEventsOfPlainFieldsReplaceTheField) {
    // VRML97 Extrusion: `eventIn set_spine` and `field spine` (freewrl test 41 wiggles a snake so);
    // fraction 0.5 of a 2 s loop at t = 1: half way, spine (1 0 0, 1 2 0).
    World w(R"(
DEF Clock TimeSensor { loop TRUE cycleInterval 2 }
DEF Wiggle CoordinateInterpolator { key [0 1] keyValue [0 0 0, 0 1 0,  2 0 0, 2 3 0] }
Shape { geometry DEF Snake Extrusion { spine [0 0 0, 0 1 0] } }
ROUTE Clock.fraction_changed TO Wiggle.set_fraction
ROUTE Wiggle.value_changed TO Snake.set_spine
)");
    EXPECT_TRUE(w.messages().empty()) << w.messages();
    EXPECT_TRUE(w.animator->evaluate(1.0));
    EXPECT_EQ(w.field("Snake", "spine"), (std::vector<double>{1, 0, 0, 1, 2, 0}));
}

TEST(Routes, ManyFramesHoldOneFramesValues) {
    // A sequence evaluates the tree once a frame: the pools must not grow with the frame count.
    World w(R"(
DEF Clock TimeSensor { loop TRUE }
DEF P CoordinateInterpolator { key [0 1] keyValue [0 0 0, 1 1 1,  5 5 5, 6 6 6] }
DEF C Coordinate { point [0 0 0, 0 0 0] }
ROUTE Clock.fraction_changed TO P.set_fraction
ROUTE P.value_changed TO C.set_point
)");
    w.animator->evaluate(0.0);
    const size_t numbers = w.loaded.tree.numbers.size();
    for (int k = 1; k <= 100; ++k) w.animator->evaluate(k / 128.0);
    EXPECT_EQ(w.loaded.tree.numbers.size(), numbers);
    // 100/128 of the way: 5 * 100/128 = 3.90625 (a binary fraction, exact).
    EXPECT_EQ(w.field("C", "point"),
              (std::vector<double>{3.90625, 3.90625, 3.90625, 4.90625, 4.90625, 4.90625}));
}

TEST(Routes, PauseTimeIsIgnoredWithAWarning) {
    World w(R"(
DEF Clock TimeSensor { loop TRUE pauseTime 0.25 }
DEF S ScalarInterpolator { key [0 1] keyValue [0 1] }
DEF M Material {}
ROUTE Clock.fraction_changed TO S.set_fraction
ROUTE S.value_changed TO M.transparency
)",
            "#X3D V3.3 utf8\nPROFILE Interchange\n");
    EXPECT_NE(w.messages().find("pauseTime and resumeTime are ignored"), std::string::npos)
        << w.messages();
    w.animator->evaluate(0.5);
    EXPECT_EQ(w.field("M", "transparency"), std::vector<double>{0.5});  // runs on past 0.25
}

}  // namespace
}  // namespace vr
