// The one bridge between MeshLab (MeshDocument / CMeshO, 2020.09 API) and the
// engine's Scene: layers in, per-vertex results out, parameter tables to
// RichParameterList and back. Plugins call this and contain no algorithm code.
#pragma once
#include <QString>
#include <functional>
#include <string>
#include <vector>

#include <common/interfaces.h>

#include "gi/params.h"
#include "gi/refine.h"
#include "gi/run.h"
#include "gi/scene.h"
#include "gi/scene_setup.h"

namespace gi::ml {

struct LayerPart {
  MeshModel* mm = nullptr;
  std::vector<int> sceneVertex;  // per cm.vert index: scene vertex, -1 if deleted
  size_t vertexOffset = 0, vertexCount = 0;
  size_t faceOffset = 0, faceCount = 0;
};

struct BridgeScene {
  Scene scene;
  MeshAttributes attrs;
  std::vector<LayerPart> parts;
};

// Layers taking part: the current one, or every visible one (extent enum of
// geometrySceneSpecs()). Throws std::invalid_argument if there is none.
std::vector<MeshModel*> participatingLayers(MeshDocument& md, int sceneExtent);
// Converts the layers (deleted elements skipped) into one scene. Throws
// std::invalid_argument when there is nothing to work on (no faces).
BridgeScene toScene(const std::vector<MeshModel*>& layers);

// Dialog <-> engine parameters. Distances become RichAbsPerc over the diagonal.
void addParams(RichParameterList& out, const std::vector<ParamSpec>& specs, double diagonal);
ParamValues readParams(const RichParameterList& in, const std::vector<ParamSpec>& specs);
// Diagonal of the layers' bounding boxes (current layer or all visible ones).
double documentDiagonal(MeshDocument& md);

// Writes quality and colour to every vertex of every part (non-finite values
// become 0 and are counted in the return value). Colour is skipped if empty.
size_t writeVertexResults(BridgeScene& b, const std::vector<float>& quality, const std::vector<Rgb8>& colors);
// The same per face (scene face order).
size_t writeFaceResults(BridgeScene& b, const std::vector<float>& quality, const std::vector<Rgb8>& colors);
// Per-vertex Point3m attribute `name` (e.g. "BentNormal"), optionally into the normals too.
void writeVertexVectorAttribute(BridgeScene& b, const std::string& name, const std::vector<glm::vec3>& v,
                                bool alsoNormals);
// Per-vertex scalar attribute `name` (e.g. "StdError").
void writeVertexScalarAttribute(BridgeScene& b, const std::string& name, const std::vector<float>& v);
// Multiplies existing vertex colours by a factor in [0,1] (AO "multiply colour").
void multiplyVertexColors(BridgeScene& b, const std::vector<float>& factor);

// Replaces each layer's geometry by its part of `m`, a refinement of
// b.scene (faces whose sourceFace lies in the layer's face range): old
// vertices stay, new ones are appended (position, normal, colour and quality
// interpolated), faces keep colour, quality and selection of their source
// face; topology, face normals and bounding box are updated. Then b (scene,
// attributes, parts) is indexed as toScene would index the new layers, and
// Bvertex / Bface (given on m.scene) are permuted to match. (mesh_replace.cpp)
void replaceWithRefined(BridgeScene& b, const RefinedMesh& m, std::vector<glm::vec3>& Bvertex,
                        std::vector<glm::vec3>& Bface);

// MeshLab progress callback -> engine progress (cancellation not supported by 2020.09's cb).
ProgressFn progressFrom(vcg::CallBackPos* cb);

// Runs `body`; converts engine exceptions into errorMessage + a log line + false.
// `log` prints one line into MeshLab's log (shown by the GUI and meshlabserver).
bool guarded(QString& errorMessage, const std::function<void(const std::string&)>& log, const QString& filter,
             const std::function<void()>& body);

}  // namespace gi::ml

namespace gi::ml {

// Everything a filter does before its algorithm: parameters read and
// validated, layers gathered into a scene, scene conventions applied.
struct PreparedRun {
  ParamValues values;
  BridgeScene bridge;
  SceneReport report;
  std::string setupLog;  // reflectance / emitters summary
};
PreparedRun prepare(MeshDocument& md, const RichParameterList& par, const std::vector<ParamSpec>& specs,
                    bool withEmitters);

}  // namespace gi::ml

namespace gi {
struct VertexRadiometry;
}
namespace gi::ml {
// Writes B as quality (luminance) and display colour; adds the exposure to the stats.
void writeRadiometry(PreparedRun& run, VertexRadiometry& r);
// Per-vertex radiosity and, optionally, per-face radiosity with the same exposure.
void writeRadiosity(PreparedRun& run, const std::vector<glm::vec3>& Bvertex, const std::vector<glm::vec3>& Bface,
                    bool faces, RunStats& stats);
}  // namespace gi::ml
