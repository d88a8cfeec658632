#include "scene/save.h"

#include <nlohmann/json.hpp>

#include "core/file_write.h"
#include "scene/display_fields.h"
#include "scene/json_reader.h"

namespace kr {

namespace {

// Keys in the order the brief's files use, so a saved file diffs well against its source
// (Json is nlohmann::ordered_json, scene/json_reader.h).

Json vec3(const Vec3& v) { return Json::array({v.x, v.y, v.z}); }

Json camera_json(const Camera& c) {
    Json j;
    j["id"] = c.id;
    j["type"] = camera_type_names.name(c.type);
    if (c.type == CameraType::lens) {
        j["focal distance"] = c.focal_distance;
        j["alpha"] = c.alpha;
    }
    j["fov"] = c.fov;
    j["aspect"] = c.aspect;
    j["distance"] = c.distance;
    j["position"] = vec3(c.position);
    j["target"] = vec3(c.target);
    return j;
}

Json material_json(const Material& m) {
    Json j;
    j["id"] = m.id;
    j["type"] = material_type_names.name(m.type);
    for (const MaterialParam& param : material_params(m.type)) {
        if (param.colour) j[std::string(param.name)] = vec3(m.*param.colour);
        else j[std::string(param.name)] = m.*param.number;
    }
    return j;
}

}  // namespace

std::string scene_to_json(const Scene& scene) {
    // Indices are checked here, not trusted: a bad one would write a file that cannot load.
    auto id_of = [](const auto& items, int index, const char* what) -> const std::string& {
        if (index < 0 || size_t(index) >= items.size())
            throw std::runtime_error(std::string("scene_to_json: ") + what + " index " + std::to_string(index) +
                                     " out of range");
        return items[size_t(index)].id;
    };
    // Every DOM here is freed without allocating however the function is left (json_reader.h):
    // a scene of 100,000 spheres can run out of memory while its DOM is being built. The two
    // objects holding the long arrays get their five keys' room first: a growing ordered_map
    // copies its members (their const keys make the pairs' moves ones that may throw), the
    // arrays' whole contents with them.
    Json root = Json::object();
    const ReleasedOnExit<Json> freed_root{root};
    root.get_ref<Json::object_t&>().reserve(5);
    root["cameras"] = Json::array();
    for (const Camera& c : scene.cameras) root["cameras"].push_back(camera_json(c));
    root["materials"] = Json::array();
    for (const Material& m : scene.materials) root["materials"].push_back(material_json(m));
    root["shapes"] = Json::array();
    for (const Shape& s : scene.shapes) {
        Json j;
        const ReleasedOnExit<Json> freed{j};
        j["id"] = s.id;
        j["type"] = shape_type_names.name(s.type);
        j["centre"] = vec3(s.centre);
        j["radius"] = s.radius;
        root["shapes"].push_back(std::move(j));
    }
    root["lights"] = Json::array();
    for (const Light& l : scene.lights) {
        Json j;
        const ReleasedOnExit<Json> freed{j};
        j["id"] = l.id;
        j["type"] = light_type_names.name(l.type);
        for (const LightParam& param : light_params(l.type)) {
            const std::string key(param.name);
            if (param.kind == LightFieldKind::shape) j[key] = id_of(scene.shapes, l.*param.shape, ("light " + key).c_str());
            else j[key] = vec3(l.*param.value);
        }
        root["lights"].push_back(std::move(j));
    }
    Json block = Json::object();
    const ReleasedOnExit<Json> freed_block{block};
    block.get_ref<Json::object_t&>().reserve(5);
    block["camera"] = id_of(scene.cameras, scene.camera, "camera");
    block["lights"] = Json::array();
    for (int l : scene.active_lights) block["lights"].push_back(id_of(scene.lights, l, "active light"));
    block["primitives"] = Json::array();
    for (const Primitive& p : scene.primitives) {
        Json j;
        const ReleasedOnExit<Json> freed{j};
        j["id"] = p.id;
        j["type"] = primitive_type_names.name(p.type);
        j["shape"] = id_of(scene.shapes, p.shape, "primitive shape");
        if (p.type == PrimitiveType::emissive) j["light"] = id_of(scene.lights, p.light, "primitive light");
        j["material"] = id_of(scene.materials, p.material, "primitive material");
        block["primitives"].push_back(std::move(j));
    }
    const RendererSettings& r = scene.renderer;
    Json renderer;
    renderer["type"] = renderer_type_names.name(r.type);
    renderer["dimensions"] = Json::array({r.width, r.height});
    renderer["samples"] = r.samples;
    renderer["depth"] = r.depth;
    renderer["output"] = r.output;
    block["renderer"] = renderer;
    Json display;
    for (const DisplayField& field : display_fields())
        if (std::optional<Json> value = field.write(scene.display)) display[std::string(field.key)] = std::move(*value);
    block["display"] = display;
    root["scene"] = std::move(block);
    // nlohmann prints doubles in their shortest round-trip form, so values load back equal.
    return root.dump(2) + "\n";
}

void save_scene_json(const Scene& scene, const std::filesystem::path& file) {
    write_file_atomic(file, scene_to_json(scene_moved_to(scene, file)));
}

Scene scene_moved_to(const Scene& scene, const std::filesystem::path& file) {
    namespace fs = std::filesystem;
    Scene moved = scene;
    moved.source_file = file;
    const fs::path dir = file.parent_path();
    if (!scene.renderer.output.empty()) {
        // Same target file seen from the new folder; absolute when no relative path exists.
        const fs::path target = scene.output_path();
        const fs::path base = fs::absolute(dir.empty() ? fs::path(".") : dir).lexically_normal();
        const fs::path absolute_target = fs::absolute(target).lexically_normal();
        fs::path relative = absolute_target.lexically_relative(base);
        moved.renderer.output = (relative.empty() ? absolute_target : relative).generic_string();
    }
    return moved;
}

}  // namespace kr
