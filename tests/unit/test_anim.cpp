// Animation at time T (docs/animation.md): the interpolators' functions, the TimeSensor's cycles,
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
    // An axis that is not unit length is normalised (docs/input.md): same as above.
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

TEST(TimeSensor, ARunThatEndedBeforeTheWorldLoadedSendsNothing) {
    // The world begins at 0: a sensor whose run ended by then was never active in it (X3D 8.2.4),
    // so it has sent no event, not the fraction 1 of an end it never reached in this world.
    EXPECT_FALSE(sensor(1, false, -9, -10, 0).sent);  // one cycle, -9 .. -8
    EXPECT_FALSE(sensor(1, false, -9, -10, 5).sent);
    EXPECT_FALSE(sensor(1, false, -1, 0, 0).sent);   // ends at the very moment of loading
    EXPECT_FALSE(sensor(1, true, -10, -5, 3).sent);  // a loop stopped at -5
    EXPECT_FALSE(sensor(4, true, -1, 0, 2).sent);    // a loop stopped as the world loads
    // Still running when the world loads: the events of now, as always.
    TimeSensorState s = sensor(2, false, -1, -1, 0.5);
    EXPECT_TRUE(s.sent && s.active);
    EXPECT_EQ(s.fraction, 0.75);
    EXPECT_TRUE(sensor(1, true, -9, -10, 0).active);  // stopTime <= startTime: loops on
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

TEST(Routes, UnknownEventsWarnAndEmptyScriptsAreSilent) {
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
    // A Script without a url has nothing to run (docs/scripts.md): no warning. (--no-scripts
    // warns once per Script: ScriptRun.NoScriptsLeavesFileValues.)
    EXPECT_EQ(text.find("Script"), std::string::npos) << text;
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

TEST(Routes, XmlProtoBodyIsEventsAsInTheClassicEncoding) {
    // Routes.ProtoBodyRoutesAndIsEvents in XML: <connect> of an inputOnly field, and of an
    // outputOnly one whose events leave the instance for another Transform.
    World w(R"(<X3D><Scene>
<ProtoDeclare name="Mover"><ProtoInterface>
  <field name="set_f" type="SFFloat" accessType="inputOnly"/>
  <field name="moved" type="SFVec3f" accessType="outputOnly"/>
</ProtoInterface><ProtoBody>
  <Transform DEF="Body"><Shape><Box/></Shape></Transform>
  <PositionInterpolator DEF="Interp" key="0 1" keyValue="0 0 0 1 0 0"><IS>
    <connect nodeField="set_fraction" protoField="set_f"/>
    <connect nodeField="value_changed" protoField="moved"/>
  </IS></PositionInterpolator>
  <ROUTE fromNode="Interp" fromField="value_changed" toNode="Body" toField="set_translation"/>
</ProtoBody></ProtoDeclare>
<ProtoInstance DEF="M1" name="Mover"/>
<ProtoInstance DEF="M2" name="Mover"/>
<Transform DEF="Follower"/>
<TimeSensor DEF="Clock" loop="true" cycleInterval="2"/>
<ROUTE fromNode="Clock" fromField="fraction_changed" toNode="M1" toField="set_f"/>
<ROUTE fromNode="M1" fromField="moved" toNode="Follower" toField="set_translation"/>
</Scene></X3D>)",
            "");
    EXPECT_TRUE(w.messages().empty()) << w.messages();
    w.animator->evaluate(0.5);  // fraction 0.25
    EXPECT_EQ(w.field("Body", "translation", 0), (std::vector<double>{0.25, 0, 0}));
    EXPECT_EQ(w.field("Body", "translation", 1), (std::vector<double>{0, 0, 0}));  // not routed
    EXPECT_EQ(w.field("Follower", "translation"), (std::vector<double>{0.25, 0, 0}));
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

// ---- X3D's spline, Squad and EaseInEaseOut interpolators --------------------------------------

std::vector<double> spline(std::vector<double> key, std::vector<double> value, size_t width,
                           double f, std::vector<double> velocity = {}, bool closed = false,
                           bool normalize = false) {
    SplineOptions o;
    o.key_velocity = velocity;
    o.closed = closed;
    o.normalize_velocity = normalize;
    return interpolate_spline(key, value, width, o, f);
}

// Hermite weights at s = 0.5: h00 = h01 = 0.5, h10 = 0.125, h11 = -0.125; all the values below
// are binary fractions, exact in double precision, unless a tolerance says otherwise.
TEST(Spline, ScalarAtKeysBetweenAndOutside) {
    const std::vector<double> k{0.0, 0.5, 1.0}, v{0.0, 1.0, 3.0};
    EXPECT_EQ(spline(k, v, 1, -1.0), std::vector<double>{0.0});  // before: the first value
    EXPECT_EQ(spline(k, v, 1, 0.0), std::vector<double>{0.0});
    EXPECT_EQ(spline(k, v, 1, 0.5), std::vector<double>{1.0});
    EXPECT_EQ(spline(k, v, 1, 1.0), std::vector<double>{3.0});
    EXPECT_EQ(spline(k, v, 1, 2.0), std::vector<double>{3.0});  // after: the last
    // Open ends: T_0 = T_2 = 0, T_1 = (3 - 0) / 2 = 1.5; uniform keys scale by 2h / 2h = 1.
    // f = 0.25: 0.5 * 0 + 0.5 * 1 + 0.125 * 0 - 0.125 * 1.5 = 0.3125 (linear would be 0.5).
    EXPECT_EQ(spline(k, v, 1, 0.25), std::vector<double>{0.3125});
    // f = 0.75: 0.5 * 1 + 0.5 * 3 + 0.125 * 1.5 - 0.125 * 0 = 2.1875.
    EXPECT_EQ(spline(k, v, 1, 0.75), std::vector<double>{2.1875});
    EXPECT_TRUE(spline({}, {}, 1, 0.5).empty());  // no keys: no event
}

TEST(Spline, UnevenKeysScaleTheTangentsSoTheVelocityIsContinuous) {
    // key [0 .25 1]: h0 = 0.25, h1 = 0.75, T_1 = 1.5. Into key 1: 2 h0 / (h0 + h1) T_1 = 0.75;
    // out of it: 2 h1 / (h0 + h1) T_1 = 2.25.
    const std::vector<double> k{0.0, 0.25, 1.0}, v{0.0, 1.0, 3.0};
    EXPECT_EQ(spline(k, v, 1, 0.125), std::vector<double>{0.40625});  // 0.5 - 0.125 * 0.75
    EXPECT_EQ(spline(k, v, 1, 0.625), std::vector<double>{2.28125});  // 2 + 0.125 * 2.25
    // dv/df on both sides of key 1: 0.75 / 0.25 = 3 = 2.25 / 0.75. Tolerance: one-sided
    // differences over e = 1e-7 err by e |v''| / 2 < 1e-5 (|v''| < 100 here), rounding by 1e-9.
    const double e = 1e-7;
    const double left = (spline(k, v, 1, 0.25)[0] - spline(k, v, 1, 0.25 - e)[0]) / e;
    const double right = (spline(k, v, 1, 0.25 + e)[0] - spline(k, v, 1, 0.25)[0]) / e;
    EXPECT_NEAR(left, 3.0, 1e-4);
    EXPECT_NEAR(right, 3.0, 1e-4);
}

TEST(Spline, PositionsAndKeyVelocities) {
    // Each component alone: y runs 0 2 4, T_1 = 2, f = 0.25: 0.5 * 2 - 0.125 * 2 = 0.75.
    EXPECT_EQ(spline({0, 0.5, 1}, {0, 0, 7, 1, 2, 7, 3, 4, 7}, 3, 0.25),
              (std::vector<double>{0.3125, 0.75, 7.0}));
    const std::vector<double> k{0.0, 0.5, 1.0}, v{0.0, 1.0, 3.0};
    // One velocity a key: T = 1, -1, 4; f = 0.25: 0.5 + 0.125 * 1 - 0.125 * -1 = 0.75.
    EXPECT_EQ(spline(k, v, 1, 0.25, {1, -1, 4}), std::vector<double>{0.75});
    // normalizeVelocity: each to length D = |1 - 0| + |3 - 1| = 3: 3 -3 3; 0.5 + 0.375 + 0.375.
    EXPECT_EQ(spline(k, v, 1, 0.25, {1, -1, 4}, false, true), std::vector<double>{1.25});
    // Two velocities are the ends' tangents; key 1 keeps (3 - 0) / 2 = 1.5:
    // 0.5 + 0.125 * 4 - 0.125 * 1.5 = 0.8125.
    EXPECT_EQ(spline(k, v, 1, 0.25, {4, 0}), std::vector<double>{0.8125});
    // Another count of velocities is not used: as without any.
    EXPECT_EQ(spline(k, v, 1, 0.25, {4, 0, 1, 1}), std::vector<double>{0.3125});
}

TEST(Spline, ClosedLoopIsContinuousThroughTheLastKey) {
    // 2D, uneven keys, first value = last: closed. T_0 = T_3 = (v_1 - v_2) / 2 = (0.5 0.5).
    const std::vector<double> k{0.0, 0.25, 0.5, 1.0}, v{1, 0, 0, 1, -1, 0, 1, 0};
    // f = 0.125 (s = 0.5): out of key 0 the tangent scales by 2 h0 / (h2 + h0) = 2/3, into key 1
    // T_1 = (v_2 - v_0) / 2 = (-1 0) by 2 h0 / (h0 + h1) = 1: x = 0.5 + 0.125 / 3 + 0.125 = 2/3,
    // y = 0.5 + 0.125 / 3 = 13/24. Tolerance: 1/3 and the sums round, a few ulps.
    const std::vector<double> mid = spline(k, v, 2, 0.125, {}, true);
    EXPECT_NEAR(mid[0], 2.0 / 3.0, 1e-15);
    EXPECT_NEAR(mid[1], 13.0 / 24.0, 1e-15);
    // The velocity leaving key 0 equals the one arriving at the last key: 2 T / (h2 + h0) =
    // (4/3 4/3). Tolerance: one-sided differences over 1e-7 with |v''| < 100, as above.
    const double e = 1e-7;
    for (int c = 0; c < 2; ++c) {
        const double start = (spline(k, v, 2, e, {}, true)[c] - v[c]) / e;
        const double end = (v[c] - spline(k, v, 2, 1.0 - e, {}, true)[c]) / e;
        EXPECT_NEAR(start, 4.0 / 3.0, 1e-4) << c;
        EXPECT_NEAR(end, 4.0 / 3.0, 1e-4) << c;
    }
    // Open (closed FALSE), the ends stop: velocity 0 there (the same tolerance).
    EXPECT_NEAR((spline(k, v, 2, e)[0] - v[0]) / e, 0.0, 1e-4);
    // Closed is ignored when the last value differs from the first: T_0 = 0, so
    // f = 0.125 gives x = 0.5 + 0.125 = 0.625, y = 0.5.
    const std::vector<double> open = spline(k, {1, 0, 0, 1, -1, 0, 1, 0.5}, 2, 0.125, {}, true);
    EXPECT_EQ(open, (std::vector<double>{0.625, 0.5}));
}

TEST(Squad, AboutOneAxisAtKeysBetweenAndOutside) {
    // About +Z only, the quaternions commute: squad blends angles. Angles 0, pi/4, pi: the inner
    // angle of key 1 is a_1 - (a_2 + a_0 - 2 a_1) / 4 = pi/4 - pi/8 = pi/8 (keys 0 and 2: a).
    // f = 0.25 (u = 0.5): lerp(0, pi/4) = pi/8, lerp(0, pi/8) = pi/16, weight 2u(1-u) = 0.5:
    // pi/8 + 0.5 (pi/16 - pi/8) = 3 pi/32. f = 0.75: lerp(pi/4, pi) = 5pi/8, lerp(pi/8, pi) =
    // 9pi/16: 5pi/8 - pi/32 = 19 pi/32. Tolerance: a few trig roundings of angles < pi.
    const std::vector<double> k{0.0, 0.5, 1.0}, v{0, 0, 1, 0, 0, 0, 1, kPiD / 4, 0, 0, 1, kPiD};
    const std::vector<double> a = interpolate_squad(k, v, 0.25), b = interpolate_squad(k, v, 0.75);
    EXPECT_NEAR(a[2], 1.0, 1e-15);
    EXPECT_NEAR(a[3], 3 * kPiD / 32, 1e-14);
    EXPECT_NEAR(b[2], 1.0, 1e-15);
    EXPECT_NEAR(b[3], 19 * kPiD / 32, 1e-14);
    EXPECT_NEAR(interpolate_squad(k, v, 0.5)[3], kPiD / 4, 1e-15);  // at a key: its value
    EXPECT_EQ(interpolate_squad(k, v, -1.0), (std::vector<double>{0, 0, 1, 0}));
    EXPECT_EQ(interpolate_squad(k, v, 3.0), (std::vector<double>{0, 0, 1, kPiD}));
    EXPECT_TRUE(interpolate_squad({}, {}, 0.5).empty());
}

TEST(Squad, ThroughKeysOfDifferentAxesContinuously) {
    // X, then Y, then Z turns: just beside key 1 the rotation is key 1's (continuity); the
    // result is a unit axis. Tolerance: 1e-9 of fraction moves the rotation by ~1e-8 rad.
    const std::vector<double> k{0.0, 0.5, 1.0}, v{1, 0, 0, 0.5, 0, 1, 0, 1.0, 0, 0, 1, 1.5};
    for (double f : {0.5 - 1e-9, 0.5 + 1e-9}) {
        const std::vector<double> r = interpolate_squad(k, v, f);
        EXPECT_NEAR(r[0], 0.0, 1e-7);
        EXPECT_NEAR(r[1], 1.0, 1e-7);
        EXPECT_NEAR(r[3], 1.0, 1e-7);
    }
    const std::vector<double> m = interpolate_squad(k, v, 0.3);
    EXPECT_NEAR(m[0] * m[0] + m[1] * m[1] + m[2] * m[2], 1.0, 1e-15);
}

std::optional<double> ease(std::vector<double> key, std::vector<double> pairs, double f) {
    return ease_in_ease_out(key, pairs, f);
}

TEST(EaseInEaseOut, ModifiedFractionAtKeysBetweenAndOutside) {
    // easeOut of key 0 = 0.5, easeIn of key 1 = 0.5: S = 1, t = 1 / (2 - 1) = 1.
    const std::vector<double> k{0.0, 1.0}, e{0, 0.5, 0.5, 0};
    EXPECT_EQ(ease(k, e, -1.0), 0.0);
    EXPECT_EQ(ease(k, e, 0.0), 0.0);
    EXPECT_EQ(ease(k, e, 0.25), 0.125);     // u < eOut: t u^2 / eOut
    EXPECT_EQ(ease(k, e, 0.5), 0.5);        // t (2u - eOut)
    EXPECT_EQ(ease(k, e, 0.875), 0.96875);  // 1 - t (1 - u)^2 / eIn
    EXPECT_EQ(ease(k, e, 1.0), 1.0);
    EXPECT_EQ(ease(k, e, 2.0), 1.0);
    // S = 2 > 1: both halve to 0.5, as above.
    EXPECT_EQ(ease(k, {0, 1, 1, 0}, 0.25), 0.125);
    EXPECT_EQ(ease(k, {0, -1, 0, 0}, 0.25), 0.25);  // S < 0: u unchanged
    EXPECT_EQ(ease(k, {}, 0.25), 0.25);             // no pairs: 0 0, linear
    // Three keys: the fraction within the interval (the spec's rule): 0.75 is u = 0.5.
    EXPECT_EQ(ease({0, 0.5, 1}, {}, 0.75), 0.5);
    EXPECT_FALSE(ease({}, {}, 0.5).has_value());  // no keys: no event
}

TEST(Routes, TimeSensorEaseInEaseOutPositionInterpolator) {
    World w(R"(
DEF Clock TimeSensor { loop TRUE cycleInterval 4 }
DEF Ease EaseInEaseOut { key [0 1] easeInEaseOut [0 0.5, 0.5 0] }
DEF Mover PositionInterpolator { key [0 1] keyValue [0 0 0, 8 0 0] }
DEF T Transform {}
ROUTE Clock.fraction_changed TO Ease.set_fraction
ROUTE Ease.modifiedFraction_changed TO Mover.set_fraction
ROUTE Mover.value_changed TO T.set_translation
)",
            "#X3D V3.3 utf8\nPROFILE Immersive\n");
    EXPECT_TRUE(w.messages().empty()) << w.messages();
    w.animator->evaluate(1.0);  // fraction 0.25 -> 0.125 (above) -> x = 8 * 0.125
    EXPECT_EQ(w.field("T", "translation"), (std::vector<double>{1, 0, 0}));
    w.animator->evaluate(3.5);  // 0.875 -> 0.96875 -> 7.75
    EXPECT_EQ(w.field("T", "translation"), (std::vector<double>{7.75, 0, 0}));
}

TEST(Routes, SplineAndSquadNodesDriveFields) {
    World w(R"(
DEF Clock TimeSensor { loop TRUE cycleInterval 4 }
DEF P SplinePositionInterpolator { key [0 0.5 1] keyValue [0 0 0, 1 0 0, 3 0 0]
                                   keyVelocity [1 0 0, -1 0 0, 4 0 0] normalizeVelocity TRUE }
DEF S SplineScalarInterpolator { key [0 0.25 0.5 1] keyValue [1 0 -1 1] closed TRUE }
DEF Q SquadOrientationInterpolator { key [0 0.5 1] keyValue [0 0 1 0, 0 0 1 0.785398, 0 0 1 3] }
DEF T Transform {}
DEF M Material {}
ROUTE Clock.fraction_changed TO P.set_fraction
ROUTE Clock.fraction_changed TO S.set_fraction
ROUTE Clock.fraction_changed TO Q.set_fraction
ROUTE P.value_changed TO T.set_translation
ROUTE S.value_changed TO M.set_transparency
ROUTE Q.value_changed TO T.set_rotation
)",
            "#X3D V3.3 utf8\nPROFILE Immersive\n");
    EXPECT_TRUE(w.messages().empty()) << w.messages();
    w.animator->evaluate(1.0);  // fraction 0.25
    // As Spline.PositionsAndKeyVelocities: 1.25 with normalised velocities.
    EXPECT_EQ(w.field("T", "translation"), (std::vector<double>{1.25, 0, 0}));
    // Closed scalar, f = 0.25 is key 1: its value 0.
    EXPECT_EQ(w.field("M", "transparency"), std::vector<double>{0.0});
    // The Squad node's value is the function's (both read the same doubles).
    EXPECT_EQ(
        w.field("T", "rotation"),
        interpolate_squad(std::vector<double>{0, 0.5, 1},
                          std::vector<double>{0, 0, 1, 0, 0, 0, 1, 0.785398, 0, 0, 1, 3}, 0.25));
    // f = 0.125: T_0 = (0 - -1) / 2 = 0.5 scaled by 2 h0 / (h2 + h0) = 2/3; T_1 = (-1 - 1) / 2 =
    // -1 scaled by 1: 0.5 + 0.125 / 3 + 0.125 = 2/3 (a few ulps: 1/3 rounds).
    w.animator->evaluate(0.5);
    EXPECT_NEAR(w.field("M", "transparency")[0], 2.0 / 3.0, 1e-15);
}

}  // namespace
}  // namespace vr
