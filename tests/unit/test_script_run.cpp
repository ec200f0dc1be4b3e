// Scripts in the world at time T (docs/scripts.md, docs/animation.md): initialize() at load, the
// cascade's events, directOutput, state from frame to frame, and the limits that keep a bad script
// from stopping the render.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "anim/animator.h"
#include "parser/load.h"

namespace vr {
namespace {

NodeId def(const NodeTree& tree, std::string_view name) {
    for (NodeId id = 0; id < tree.nodes.size(); ++id)
        if (tree.def_name(id) == name) return id;
    return kNullNode;
}

std::vector<double> numbers(const NodeTree& tree, std::string_view node, std::string_view field) {
    const FieldView v = tree.get(def(tree, node), field);
    return {v.numbers.begin(), v.numbers.end()};
}

// Every warning's message, one a line, to find a text in.
std::string messages(const Diagnostics& d) {
    std::string text;
    for (const Diagnostic& x : d.all()) text += x.message + "\n";
    return text;
}

const char* const kMover =
    "#VRML V2.0 utf8\n"
    "DEF G Group {}\n"
    "DEF T Transform { translation 9 9 9 }\n"
    "DEF TS TimeSensor { cycleInterval 4 loop TRUE }\n"
    "DEF S Script {\n"
    "  eventIn SFFloat set_fraction\n"
    "  eventOut SFVec3f pos\n"
    "  eventOut MFNode made\n"
    "  url \"javascript:\n"
    "    function initialize() {\n"
    "      made = Browser.createVrmlFromString('Shape { geometry Sphere { radius 0.5 } } "
    "Shape { geometry Box { } }');\n"
    "    }\n"
    "    function set_fraction(f, t) { pos = new SFVec3f(4 * f - 2, t, 0); }\"\n"
    "}\n"
    "ROUTE TS.fraction_changed TO S.set_fraction\n"
    "ROUTE S.pos TO T.set_translation\n"
    "ROUTE S.made TO G.addChildren\n";

TEST(ScriptRun, InitializeBuildsGeometryThroughAddChildren) {
    LoadedScene scene = load_scene_text(kMover, "mover.wrl");
    ASSERT_TRUE(scene.ok());
    Diagnostics d;
    Animator animator(scene.tree, d);
    EXPECT_EQ(d.warning_count(), 0u) << messages(d);
    EXPECT_EQ(animator.scripts(), 1u);
    // The two Shapes the string holds are the Group's children from load on.
    const FieldView children = scene.tree.get(def(scene.tree, "G"), "children");
    ASSERT_EQ(children.nodes.size(), 2u);
    EXPECT_EQ(scene.tree.type_name(children.nodes[0]), "Shape");
    EXPECT_EQ(scene.tree.type_name(scene.tree.get_node(children.nodes[1], intern("geometry"))),
              "Box");
}

TEST(ScriptRun, MathRandomGivesTheSameWorldEveryRun) {
    // OpenVRML's warbird.wrl moves its boxes by Math.random(): Duktape's own generator is seeded
    // from the clock, so two renders of the file differed (the batch-against-per-file test caught
    // it). Each Script's generator now starts from a seed of its node: the same numbers every run,
    // in [0, 1), and not the same for two Scripts.
    const char* const text =
        "#VRML V2.0 utf8\n"
        "DEF T Transform {}\n"
        "DEF U Transform {}\n"
        "DEF S Script { eventOut SFVec3f pos url \"javascript: function initialize() {"
        " pos = new SFVec3f(Math.random(), Math.random(), Math.random()); }\" }\n"
        "DEF R Script { eventOut SFVec3f pos url \"javascript: function initialize() {"
        " pos = new SFVec3f(Math.random(), Math.random(), Math.random()); }\" }\n"
        "ROUTE S.pos TO T.set_translation\n"
        "ROUTE R.pos TO U.set_translation\n";
    std::vector<double> first, second;
    for (std::vector<double>* out : {&first, &second}) {
        LoadedScene scene = load_scene_text(text, "random.wrl");
        ASSERT_TRUE(scene.ok());
        Diagnostics d;
        Animator animator(scene.tree, d);
        EXPECT_EQ(d.warning_count(), 0u) << messages(d);
        *out = numbers(scene.tree, "T", "translation");
        EXPECT_NE(*out, numbers(scene.tree, "U", "translation"));
    }
    EXPECT_EQ(first, second);
    for (double x : first) {
        EXPECT_GE(x, 0.0);
        EXPECT_LT(x, 1.0);
    }
}

TEST(ScriptRun, TimeSensorThroughScriptMovesTransformAtLaterTime) {
    LoadedScene scene = load_scene_text(kMover, "mover.wrl");
    Diagnostics d;
    Animator animator(scene.tree, d);
    // t = 3: fraction 3/4 of the 4 s cycle; the script sends (4 * 0.75 - 2, t, 0) = (1, 3, 0).
    EXPECT_TRUE(animator.evaluate(3.0));
    EXPECT_EQ(numbers(scene.tree, "T", "translation"), (std::vector<double>{1, 3, 0}));
    // A later frame: t = 3.5, fraction 0.875: (1.5, 3.5, 0).
    EXPECT_TRUE(animator.evaluate(3.5));
    EXPECT_EQ(numbers(scene.tree, "T", "translation"), (std::vector<double>{1.5, 3.5, 0}));
}

TEST(ScriptRun, StateIsKeptFromFrameToFrame) {
    // A counter of events: frames at 0, 1 and 2 send it 1, 2, 3; the same time again sends
    // nothing new (the frame probe asks twice).
    LoadedScene scene = load_scene_text(
        "#VRML V2.0 utf8\n"
        "DEF SI ScalarInterpolator {}\n"
        "DEF TS TimeSensor { loop TRUE }\n"
        "DEF S Script { eventIn SFTime tick eventOut MFFloat out field SFInt32 n 0\n"
        "  url \"javascript: function tick(t) { n = n + 1; out = new MFFloat(n, t); }\" }\n"
        "ROUTE TS.time TO S.tick\n"
        "ROUTE S.out TO SI.set_key\n",
        "count.wrl");
    Diagnostics d;
    Animator animator(scene.tree, d);
    animator.evaluate(0.0);
    EXPECT_EQ(numbers(scene.tree, "SI", "key"), (std::vector<double>{1, 0}));
    animator.evaluate(1.0);
    animator.evaluate(1.0);
    EXPECT_EQ(numbers(scene.tree, "SI", "key"), (std::vector<double>{2, 1}));
    animator.evaluate(2.0);
    EXPECT_EQ(numbers(scene.tree, "SI", "key"), (std::vector<double>{3, 2}));
}

// Xj3D's groups/switch-dynamic.wrl: a Script toggles a Switch on each cycleTime. A browser sends
// cycleTime when a cycle begins (VRML97 6.50), isActive when it changes, and has drawn the load's
// frame (t = 0) before any later one: at 1.5 s it has toggled twice (at 0 and at 1), as X_ITE
// shows. Frames at 0.25 s steps send cycleTime at 0 and 1 only, so the sequence agrees with the
// single render. (Not at 1 s itself: there vrmlray's sensor reads the end of the first cycle,
// fraction 1.)
const char* const kToggle =
    "#VRML V2.0 utf8\n"
    "DEF TS TimeSensor { cycleInterval 1 loop TRUE }\n"
    "DEF C ScalarInterpolator {}\n"
    "DEF A ScalarInterpolator {}\n"
    "DEF S Script { eventIn SFTime cycleTime eventIn SFBool active\n"
    "  eventOut MFFloat cycles_out eventOut MFFloat changes_out\n"
    "  field SFInt32 cycles 0 field SFInt32 changes 0\n"
    "  url \"javascript: function cycleTime(v) { cycles = cycles + 1; cycles_out = new "
    "MFFloat(cycles); }\n"
    "    function active(v) { changes = changes + 1; changes_out = new MFFloat(changes); }\" }\n"
    "ROUTE TS.cycleTime TO S.cycleTime\n"
    "ROUTE TS.isActive TO S.active\n"
    "ROUTE S.cycles_out TO C.set_key\n"
    "ROUTE S.changes_out TO A.set_key\n";

TEST(ScriptRun, CycleTimeAtEachCycleAndTheLoadFrameFirst) {
    LoadedScene single = load_scene_text(kToggle, "toggle.wrl");
    Diagnostics d1;
    Animator once(single.tree, d1);
    once.evaluate(1.5);
    // cycleTime at 0 and 1; isActive once (TRUE at 0, no change after).
    EXPECT_EQ(numbers(single.tree, "C", "key"), (std::vector<double>{2})) << messages(d1);
    EXPECT_EQ(numbers(single.tree, "A", "key"), (std::vector<double>{1})) << messages(d1);

    LoadedScene frames = load_scene_text(kToggle, "toggle.wrl");
    Diagnostics d2;
    Animator sequence(frames.tree, d2);
    for (double t : {0.0, 0.25, 0.5, 0.75, 1.0, 1.25, 1.5}) sequence.evaluate(t);
    EXPECT_EQ(numbers(frames.tree, "C", "key"), (std::vector<double>{2})) << messages(d2);
    EXPECT_EQ(numbers(frames.tree, "A", "key"), (std::vector<double>{1})) << messages(d2);
}

TEST(ScriptRun, DirectOutputSetsFieldsOfHeldNodes) {
    // Assigned whole (translation, rotation), or changed in place through the field object the
    // node gave (scale.y): both reach the node when the call ends.
    LoadedScene scene = load_scene_text(
        "#VRML V2.0 utf8\n"
        "DEF T Transform {}\n"
        "DEF S Script { directOutput TRUE field SFNode t USE T\n"
        "  url \"javascript: function initialize() { t.translation = new SFVec3f(1, 2, 3); "
        "t.rotation = new SFRotation(0, 1, 0, 0.5); var s = t.scale; s.y = 4; }\" }\n",
        "direct.wrl");
    Diagnostics d;
    Animator animator(scene.tree, d);
    EXPECT_EQ(d.warning_count(), 0u) << messages(d);
    EXPECT_EQ(numbers(scene.tree, "T", "translation"), (std::vector<double>{1, 2, 3}));
    EXPECT_EQ(numbers(scene.tree, "T", "rotation"), (std::vector<double>{0, 1, 0, 0.5}));
    EXPECT_EQ(numbers(scene.tree, "T", "scale"), (std::vector<double>{1, 4, 1}));
}

TEST(ScriptRun, AddRouteAndDeleteRoute) {
    // initialize() routes the clock through the interpolator into T, and deletes the file's ROUTE
    // into U. At t = 1 of a 4 s cycle, fraction 1/4: T moves to (1, 0, 0) of the (0 0 0, 4 0 0)
    // keys; U keeps its file value.
    LoadedScene scene = load_scene_text(
        "#VRML V2.0 utf8\n"
        "DEF T Transform {}\n"
        "DEF U Transform { translation 0 5 0 }\n"
        "DEF TS TimeSensor { cycleInterval 4 loop TRUE }\n"
        "DEF P PositionInterpolator { key [0 1] keyValue [0 0 0, 4 0 0] }\n"
        "DEF S Script { field SFNode clock USE TS field SFNode p USE P field SFNode t USE T\n"
        "  field SFNode u USE U\n"
        "  url \"javascript: function initialize() {\n"
        "    Browser.addRoute(clock, 'fraction_changed', p, 'set_fraction');\n"
        "    Browser.addRoute(p, 'value_changed', t, 'set_translation');\n"
        "    Browser.deleteRoute(p, 'value_changed', u, 'set_translation'); }\" }\n"
        "ROUTE P.value_changed TO U.set_translation\n",
        "routes.wrl");
    Diagnostics d;
    Animator animator(scene.tree, d);
    EXPECT_EQ(d.warning_count(), 0u) << messages(d);
    EXPECT_TRUE(animator.animated());
    animator.evaluate(1.0);
    EXPECT_EQ(numbers(scene.tree, "T", "translation"), (std::vector<double>{1, 0, 0}));
    EXPECT_EQ(numbers(scene.tree, "U", "translation"), (std::vector<double>{0, 5, 0}));
}

TEST(ScriptRun, X3dXmlScriptTextIsRun) {
    LoadedScene scene = load_scene_text(
        "<X3D version='3.2'><Scene>\n"
        "<ScalarInterpolator DEF='SI'/>\n"
        "<Script DEF='S'><field accessType='outputOnly' name='out' type='MFFloat'/>\n"
        "<field accessType='initializeOnly' name='k' type='SFFloat' value='2.5'/>\n"
        "<![CDATA[ecmascript:\n"
        "function initialize() { out = new MFFloat(k, k * 2); }\n"
        "]]></Script>\n"
        "<ROUTE fromNode='S' fromField='out' toNode='SI' toField='set_key'/>\n"
        "</Scene></X3D>\n",
        "cdata.x3d");
    ASSERT_TRUE(scene.ok());
    Diagnostics d;
    Animator animator(scene.tree, d);
    EXPECT_EQ(d.warning_count(), 0u) << messages(d);
    EXPECT_EQ(numbers(scene.tree, "SI", "key"), (std::vector<double>{2.5, 5}));
}

// A Script of `body` (its url's text) beside a well-behaved one; what each limit does.
struct Bad {
    LoadedScene scene;
    Diagnostics d;
    std::unique_ptr<Animator> animator;
    Bad(const std::string& body, ScriptSettings settings) {
        scene = load_scene_text(
            "#VRML V2.0 utf8\n"
            "DEF T Transform {}\n"
            "DEF BAD Script { eventOut SFVec3f pos url \"javascript:" +
                body +
                "\" }\n"
                "DEF GOOD Script { eventOut SFVec3f pos url \"javascript: function initialize() "
                "{ pos = new SFVec3f(0, 1, 0); }\" }\n"
                "ROUTE BAD.pos TO T.set_scale\n"
                "ROUTE GOOD.pos TO T.set_translation\n",
            "bad.wrl");
        animator = std::make_unique<Animator>(scene.tree, d, &settings);
    }
};

TEST(ScriptRun, EndlessLoopIsStoppedAndNamed) {
    ScriptSettings settings;
    settings.limits.seconds_per_call = 0.2;  // the loop is stopped after 0.2 s, not the default 1
    Bad bad("\nfunction initialize() {\n  pos = new SFVec3f(5, 5, 5);\n  while (true) {}\n}",
            settings);
    const std::string text = messages(bad.d);
    EXPECT_NE(text.find("Script 'BAD': initialize() ran longer than 0.2"), std::string::npos)
        << text;
    // Duktape names the line at which its interrupt found the deadline passed: the loop's line 4,
    // and in one run on a loaded machine line 3 (the SFVec3f before the loop). Either names a line
    // of the script near the loop, which is what the user needs.
    EXPECT_TRUE(text.find("line 4 of its script") != std::string::npos ||
                text.find("line 3 of its script") != std::string::npos)
        << text;
    // Its outputs are dropped (the scale stays 1 1 1); the other Script still ran.
    EXPECT_EQ(numbers(bad.scene.tree, "T", "scale"), (std::vector<double>{1, 1, 1}));
    EXPECT_EQ(numbers(bad.scene.tree, "T", "translation"), (std::vector<double>{0, 1, 0}));
}

TEST(ScriptRun, HugeAllocationHitsTheHeapLimit) {
    ScriptSettings settings;
    settings.limits.heap_bytes = size_t(8) << 20;
    settings.limits.seconds_per_call = 20;  // memory, not time, must stop it
    Bad bad(
        "function initialize() { var a = []; for (;;) a.push(new Array(100000).join('x') + "
        "a.length); }",
        settings);
    const std::string text = messages(bad.d);
    EXPECT_NE(text.find("Script 'BAD'"), std::string::npos) << text;
    EXPECT_EQ(text.find("ran longer"), std::string::npos) << text;
    EXPECT_EQ(numbers(bad.scene.tree, "T", "translation"), (std::vector<double>{0, 1, 0}));
}

TEST(ScriptRun, ThrownExceptionIsAWarningWithTheScriptLine) {
    Bad bad(
        "\nfunction initialize() {\n  pos = new SFVec3f(5, 5, 5);\n  throw new Error('boom');\n}",
        ScriptSettings{});
    const std::string text = messages(bad.d);
    EXPECT_NE(text.find("Script 'BAD': initialize() line 4 of its script: Error: boom"),
              std::string::npos)
        << text;
    EXPECT_EQ(numbers(bad.scene.tree, "T", "scale"), (std::vector<double>{1, 1, 1}));
    EXPECT_EQ(numbers(bad.scene.tree, "T", "translation"), (std::vector<double>{0, 1, 0}));
}

// X3D's scene API: createNode makes a node of the type with its defaults; a member vrmlray lacks
// (createProto, used by Titania's tests) is one warning that names it, not a bare TypeError.
TEST(ScriptRun, CurrentSceneCreatesNodesAndNamesWhatItLacks) {
    LoadedScene scene = load_scene_text(
        "#X3D V3.0 utf8\n"
        "DEF G Group {}\n"
        "DEF S Script {\n"
        "  outputOnly MFNode made\n"
        "  url \"ecmascript:\n"
        "    function initialize() {\n"
        "      var shape = Browser.currentScene.createNode('Shape');\n"
        "      shape.geometry = Browser.currentScene.createNode('Sphere');\n"
        "      shape.geometry.radius = 2;\n"
        "      made = new MFNode(shape);\n"
        "      Browser.currentScene.createProto('Cube');\n"
        "    }\"\n"
        "}\n"
        "ROUTE S.made TO G.addChildren\n",
        "scene_api.x3dv");
    ASSERT_TRUE(scene.ok());
    Diagnostics d;
    Animator animator(scene.tree, d);
    const FieldView children = scene.tree.get(def(scene.tree, "G"), "children");
    ASSERT_EQ(children.nodes.size(), 1u) << messages(d);
    const NodeId sphere = scene.tree.get_node(children.nodes[0], intern("geometry"));
    EXPECT_EQ(scene.tree.type_name(sphere), "Sphere");
    EXPECT_EQ(scene.tree.get(sphere, "radius").numbers[0], 2.0);
    EXPECT_EQ(d.warning_count(), 1u) << messages(d);
    EXPECT_NE(messages(d).find("Browser.currentScene.createProto is not supported"),
              std::string::npos)
        << messages(d);
}

TEST(ScriptRun, NoScriptsLeavesFileValues) {
    LoadedScene scene = load_scene_text(kMover, "mover.wrl");
    Diagnostics d;
    ScriptSettings off;
    off.enabled = false;
    Animator animator(scene.tree, d, &off);
    EXPECT_EQ(animator.scripts(), 0u);
    animator.evaluate(3.0);
    EXPECT_EQ(numbers(scene.tree, "T", "translation"), (std::vector<double>{9, 9, 9}));
    EXPECT_EQ(scene.tree.get(def(scene.tree, "G"), "children").nodes.size(), 0u);
    // Once per Script, however many of its outputs are routed (pos and made here).
    EXPECT_NE(messages(d).find("Script 'S' is not run (--no-scripts)"), std::string::npos);
    EXPECT_EQ(messages(d).find("(2 times)"), std::string::npos) << messages(d);
}

TEST(ScriptRun, FileWithoutScriptsStartsNoEngine) {
    LoadedScene scene = load_scene_text(
        "#VRML V2.0 utf8\nDEF T Transform {}\nDEF TS TimeSensor {}\n"
        "DEF P PositionInterpolator { key [0 1] keyValue [0 0 0 1 1 1] }\n"
        "ROUTE TS.fraction_changed TO P.set_fraction ROUTE P.value_changed TO T.set_translation\n",
        "plain.wrl");
    Diagnostics d;
    Animator animator(scene.tree, d);
    EXPECT_TRUE(scene.tree.scripts.empty());
    EXPECT_EQ(animator.scripts(), 0u);
}

TEST(ScriptRun, JsFileUrlObeysTheSandbox) {
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / ("vrmlray_script_" + std::to_string(getpid()));
    std::filesystem::create_directories(dir / "scene");
    std::ofstream(dir / "scene" / "move.js")
        << "function initialize() { pos = new SFVec3f(7, 8, 9); }\n";
    std::ofstream(dir / "outside.js") << "function initialize() { pos = new SFVec3f(1, 1, 1); }\n";
    std::ofstream(dir / "scene" / "a.wrl")
        << "#VRML V2.0 utf8\nDEF T Transform {}\n"
           "DEF S Script { eventOut SFVec3f pos url \"move.js\" }\n"
           "DEF O Script { eventOut SFVec3f pos url \"../outside.js\" }\n"
           "ROUTE S.pos TO T.set_translation ROUTE O.pos TO T.set_scale\n";
    LoadOptions options;
    options.sandbox = true;
    LoadedScene scene = load_scene(dir / "scene" / "a.wrl", options);
    ASSERT_TRUE(scene.ok());
    ScriptSettings settings;
    settings.sources = &scene.sources;
    settings.allowed_roots = scene.allowed_roots;
    Diagnostics d;
    Animator animator(scene.tree, d, &settings);
    EXPECT_EQ(numbers(scene.tree, "T", "translation"), (std::vector<double>{7, 8, 9}));
    EXPECT_EQ(numbers(scene.tree, "T", "scale"), (std::vector<double>{1, 1, 1}));  // file value
    EXPECT_NE(messages(d).find("Script 'O' is not run: its url gives no script"), std::string::npos)
        << messages(d);
    std::filesystem::remove_all(dir);
}

TEST(ScriptRun, NanNeverReachesTheScene) {
    // 0/0 is NaN and 1/0 infinity: each becomes 0, with a warning.
    LoadedScene scene = load_scene_text(
        "#VRML V2.0 utf8\n"
        "DEF T Transform {}\n"
        "DEF S Script { eventOut SFVec3f pos url \"javascript: function initialize() "
        "{ pos = new SFVec3f(0 / 0, 1, 1 / 0); }\" }\n"
        "ROUTE S.pos TO T.set_translation\n",
        "nan.wrl");
    Diagnostics d;
    Animator animator(scene.tree, d);
    EXPECT_EQ(numbers(scene.tree, "T", "translation"), (std::vector<double>{0, 1, 0}));
    EXPECT_NE(messages(d).find("Script 'S' sent NaN or infinity in pos"), std::string::npos)
        << messages(d);
}

}  // namespace
}  // namespace vr
