// VRML 1.0 (`#VRML V1.0 ascii`): read with the classic tokenizer and value parser against
// grammar/vrml1.nodes, then upgraded into VRML97 nodes of the node tree the other readers fill.
//
// The upgrade follows the VRML 1.0 traversal-state semantics:
// * Separator (and WWWAnchor) save and restore the whole state; Group passes state on;
//   TransformSeparator restores only the transformation; Switch and LOD traverse their chosen
//   child (the others are kept in a VRML97 Switch/LOD, each read with its own copy of the state).
// * Translation, Rotation, Scale, Transform and MatrixTransform accumulate one matrix. Each
//   Separator becomes a Group whose content is relative to where the Separator starts; shapes,
//   cameras and nested Separators under the same accumulated matrix share one VRML97 Transform
//   holding that matrix (decomposed exactly: see parser/vrml1_affine.h). No Transform chain grows
//   with the number of Translation nodes, so RasMol's long runs of Translation deltas stay flat.
// * Material, MaterialBinding, Coordinate3, Normal, NormalBinding, TextureCoordinate2, Texture2,
//   Texture2Transform and ShapeHints are state read by the shapes that follow; a Material with
//   several values becomes Color nodes (per face/vertex bindings) or separate parts (Cylinder,
//   Cone, Cube).
// * Lights are placed in the group of the Separator they stand in, with their position and
//   direction transformed by the matrix at that point. VRML97 scopes a DirectionalLight to its
//   whole parent group, so shapes earlier in the same Separator are lit too (VRML 1.0 lights only
//   what follows). Point and spot lights inside a Separator get the X3D field `global FALSE` for
//   the same scoping; at the top level they stay VRML97 global lights.
// * PerspectiveCamera becomes a Viewpoint whose fieldOfView is heightAngle. VRML 1.0's heightAngle
//   spans the vertical side, VRML97's fieldOfView the smaller side: the two agree for landscape
//   and square images, and a portrait image shows a wider vertical angle. OrthographicCamera
//   becomes an X3D OrthoViewpoint with fieldOfView [-h/2 -h/2 h/2 h/2] (same landscape rule).
// * ShapeHints: CLOCKWISE gives ccw FALSE; solid TRUE needs shapeType SOLID and a known vertex
//   order (with UNKNOWN_ORDERING VRML 1.0 lights both sides, so culling would be wrong); faceType
//   UNKNOWN_FACE_TYPE gives convex FALSE; creaseAngle carries over (VRML 1.0 default 0.5).
// * Material: VRML97 has one ambient intensity (the mean of ambientColor), and per-face/vertex
//   colours replace only the diffuse colour, so the other properties come from the Material's
//   first value. A Material with empty ambient, diffuse and specular lists holds precomputed
//   (emissive) colours and is drawn unlit.
// * AsciiText becomes a VRML97 Text with a FontStyle made from the last VRML 1.0 FontStyle (size,
//   family, style) and its own spacing and justification (LEFT, CENTER, RIGHT as BEGIN, MIDDLE,
//   END); its `width` values become `length`. Info is dropped.
#pragma once
#include "parser/classic.h"
#include "parser/load.h"

namespace vr {

// Reads the VRML 1.0 text of source file `file` (already in scene.sources) into scene.tree as
// VRML97 nodes.
ClassicResult read_vrml1(LoadedScene& scene, uint32_t file, const LoadLimits& limits);

}  // namespace vr
