// Model loading with assimp (OBJ, glTF 2.0 and whatever else assimp reads) into body frames.
#include "scene/models/triangle_mesh.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <assimp/Importer.hpp>

#include "scene/core/error.h"

namespace seasense::scene {

TriangleMesh LoadModel(const std::filesystem::path& file, double scale) {
    Assimp::Importer importer;
    // PreTransformVertices flattens the node hierarchy into mesh space; GenNormals adds flat
    // normals only where the file has none, so authored smoothing is kept.
    const aiScene* s =
        importer.ReadFile(file.string(), aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                             aiProcess_PreTransformVertices | aiProcess_GenNormals |
                                             aiProcess_SortByPType | aiProcess_FindInvalidData);
    if (!s || (s->mFlags & AI_SCENE_FLAGS_INCOMPLETE) || s->mNumMeshes == 0) {
        throw InputError(file.string() + ": cannot load model: " +
                         (s ? std::string("no meshes in file") : importer.GetErrorString()));
    }
    TriangleMesh mesh;
    const float fscale = float(scale);
    for (unsigned m = 0; m < s->mNumMeshes; ++m) {
        const aiMesh* am = s->mMeshes[m];
        if (!(am->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;  // skip lines/points
        const uint32_t base = uint32_t(mesh.positions.size());
        for (unsigned v = 0; v < am->mNumVertices; ++v) {
            const aiVector3D p = am->mVertices[v];
            // glTF axes → body axes: right = −X, forward = +Z, up = +Y (a proper rotation).
            mesh.positions.push_back(glm::vec3(-p.x, p.z, p.y) * fscale);
            const aiVector3D n = am->mNormals ? am->mNormals[v] : aiVector3D(0, 1, 0);
            mesh.normals.push_back(glm::normalize(glm::vec3(-n.x, n.z, n.y)));
        }
        for (unsigned f = 0; f < am->mNumFaces; ++f) {
            const aiFace& face = am->mFaces[f];
            if (face.mNumIndices != 3) continue;
            for (int i = 0; i < 3; ++i) mesh.indices.push_back(base + face.mIndices[i]);
        }
    }
    if (mesh.indices.empty()) throw InputError(file.string() + ": model has no triangles");
    return mesh;
}

TriangleMesh TransformMesh(const TriangleMesh& body, const Pose& pose) {
    TriangleMesh out;
    out.indices = body.indices;
    out.positions.reserve(body.positions.size());
    out.normals.reserve(body.normals.size());
    for (const glm::vec3& p : body.positions) out.positions.push_back(glm::vec3(pose.ToWorld(p)));
    for (const glm::vec3& n : body.normals)
        out.normals.push_back(glm::vec3(glm::normalize(pose.worldFromBody * glm::dvec3(n))));
    return out;
}

}  // namespace seasense::scene
