#include "tests/support/test_scenes.h"

namespace vrl::test {

namespace {
MediumDescription medium(const std::string& id, const Rgb& sigmaS, const Rgb& sigmaA, float g) {
    MediumDescription m;
    m.id = id;
    m.sigmaS = sigmaS;
    m.sigmaA = sigmaA;
    if (g != 0.0f) m.phase = {PhaseDescription::Kind::HenyeyGreenstein, g};
    return m;
}
}  // namespace

SensorDescription cameraAtOrigin(int width, int height, float fovDegrees) {
    SensorDescription sensor;
    sensor.toWorld = Transform::lookAt(Vec3(0, 0, 0), Vec3(0, 0, 1), Vec3(0, 1, 0));
    sensor.fov = fovDegrees;
    sensor.width = width;
    sensor.height = height;
    sensor.nearClip = 1e-4f;
    return sensor;
}

SceneDescription cameraAndFarLight(int width, int height, float fovDegrees) {
    SceneDescription d;
    d.sensor = cameraAtOrigin(width, height, fovDegrees);
    EmitterDescription light;
    light.toWorld = Transform::translate(Vec3(0, 50, 0));
    d.emitters.push_back(light);
    return d;
}

SceneDescription emittingSphereFurnace(const Rgb& radiance, const Rgb& sigmaS, float g, const Rgb& wallReflectance) {
    SceneDescription scene;
    scene.sensor = cameraAtOrigin(8, 8, 90.0f);
    scene.media.push_back(medium("furnace", sigmaS, Rgb(0.0f), g));
    scene.sensor.medium = 0;
    ShapeDescription sphere;
    sphere.kind = ShapeDescription::Kind::Sphere;
    sphere.radius = 1.0f;
    sphere.flipNormals = true;  // emit towards the centre
    sphere.bsdf = test::diffuseBsdf(wallReflectance, false);
    sphere.areaRadiance = radiance;
    sphere.exteriorMedium = 0;  // flipped: the inside is the exterior side
    scene.shapes.push_back(sphere);
    return scene;
}

SceneDescription absorberSlab(const Rgb& radiance, const Rgb& sigmaA, float thickness) {
    SceneDescription scene;
    scene.sensor = cameraAtOrigin(9, 9, 20.0f);
    scene.media.push_back(medium("absorber", Rgb(0.0f), sigmaA, 0.0f));
    ShapeDescription slab;
    slab.kind = ShapeDescription::Kind::Cube;
    slab.toWorld = Transform::scale(Vec3(10.0f, 10.0f, 0.5f * thickness)).then(Transform::translate(Vec3(0, 0, 3)));
    slab.bsdf = test::nullBsdf();
    slab.interiorMedium = 0;
    scene.shapes.push_back(slab);
    ShapeDescription light;
    light.kind = ShapeDescription::Kind::Rectangle;
    // Rectangle faces +z; rotate it to face the camera (-z), 8 units away.
    light.toWorld = Transform::scale(Vec3(5.0f)).then(Transform::rotate(Vec3(1, 0, 0), 180.0f)).then(
        Transform::translate(Vec3(0, 0, 8)));
    light.areaRadiance = radiance;
    scene.shapes.push_back(light);
    return scene;
}

SceneDescription pointLightInInfiniteMedium(const Rgb& intensity, const Vec3& lightPosition, const Rgb& sigmaS,
                                           const Rgb& sigmaA, float g) {
    SceneDescription scene;
    scene.sensor = cameraAtOrigin(4, 4, 60.0f);
    scene.media.push_back(medium("fog", sigmaS, sigmaA, g));
    scene.sensor.medium = 0;
    EmitterDescription light;
    light.kind = EmitterDescription::Kind::Point;
    light.intensity = intensity;
    light.toWorld = Transform::translate(lightPosition);
    scene.emitters.push_back(light);
    return scene;
}

SceneDescription sphereInMedium(const Rgb& sigmaS, const Rgb& sigmaA, float g, const BsdfDescription& bsdf,
                                bool boxed) {
    SceneDescription d = pointLightInInfiniteMedium(Rgb(1.0f), Vec3(0.0f, 3.0f, 0.0f), sigmaS, sigmaA, g);
    d.sensor.toWorld = Transform::lookAt(Vec3(0, 0, -3.5f), Vec3(0, 0, 0), Vec3(0, 1, 0));
    ShapeDescription sphere;
    sphere.kind = ShapeDescription::Kind::Sphere;
    sphere.radius = 1.0f;
    sphere.bsdf = bsdf;
    d.shapes.push_back(sphere);
    if (boxed) {
        ShapeDescription box;
        box.kind = ShapeDescription::Kind::Cube;
        box.toWorld = Transform::scale(Vec3(4.0f));
        box.bsdf = nullBsdf();
        box.interiorMedium = 0;
        d.shapes.push_back(box);
    }
    return d;
}

SceneDescription mediumOnlyCube(const Rgb& sigmaS, const Rgb& sigmaA, float g) {
    SceneDescription scene;
    scene.sensor = cameraAtOrigin(16, 16, 40.0f);
    scene.sensor.toWorld = Transform::lookAt(Vec3(0.3f, 0.2f, -3.5f), Vec3(0, 0, 0), Vec3(0, 1, 0));
    scene.media.push_back(medium("cube", sigmaS, sigmaA, g));
    ShapeDescription cube;
    cube.kind = ShapeDescription::Kind::Cube;
    cube.bsdf = test::nullBsdf();
    cube.interiorMedium = 0;
    scene.shapes.push_back(cube);
    EmitterDescription light;
    light.kind = EmitterDescription::Kind::Point;
    light.intensity = Rgb(3.0f);
    light.toWorld = Transform::translate(Vec3(0.2f, 0.5f, 0.3f));
    light.medium = 0;
    scene.emitters.push_back(light);
    return scene;
}

SceneDescription litRoomWithOccluder(const Rgb& sigmaS, const Rgb& sigmaA, float g) {
    SceneDescription scene;
    scene.sensor = cameraAtOrigin(16, 16, 75.0f);
    scene.sensor.toWorld = Transform::lookAt(Vec3(0.2f, 0.3f, -1.9f), Vec3(0, -0.4f, 1), Vec3(0, 1, 0));
    scene.media.push_back(medium("smoke", sigmaS, sigmaA, g));
    scene.sensor.medium = 0;
    ShapeDescription room;
    room.kind = ShapeDescription::Kind::Cube;
    room.toWorld = Transform::scale(Vec3(2.0f));
    room.bsdf = test::diffuseBsdf(Rgb(0.6f, 0.55f, 0.5f), true);
    scene.shapes.push_back(room);
    ShapeDescription occluder;
    occluder.kind = ShapeDescription::Kind::Cube;
    occluder.toWorld = Transform::scale(Vec3(0.5f, 0.8f, 0.5f)).then(Transform::rotate(Vec3(0, 1, 0), 25.0f)).then(
        Transform::translate(Vec3(0.4f, -1.2f, 0.6f)));
    occluder.bsdf = test::diffuseBsdf(Rgb(0.3f, 0.5f, 0.7f), false);
    scene.shapes.push_back(occluder);
    ShapeDescription panel;
    panel.kind = ShapeDescription::Kind::Rectangle;
    panel.toWorld = Transform::scale(Vec3(0.4f)).then(Transform::rotate(Vec3(1, 0, 0), 90.0f)).then(
        Transform::translate(Vec3(-0.8f, 1.95f, 0.8f)));  // +z rotated to -y: faces the floor
    panel.areaRadiance = Rgb(6.0f, 5.0f, 4.0f);
    panel.bsdf = test::diffuseBsdf(Rgb(0.0f), false);
    scene.shapes.push_back(panel);
    EmitterDescription spot;
    spot.kind = EmitterDescription::Kind::Spot;
    spot.intensity = Rgb(12.0f);
    spot.cutoffAngle = 35.0f;
    spot.beamWidth = 25.0f;
    spot.toWorld = Transform::lookAt(Vec3(1.2f, 1.6f, -0.5f), Vec3(0.2f, -2.0f, 0.8f), Vec3(0, 0, 1));
    scene.emitters.push_back(spot);
    return scene;
}

namespace {

// A 1.8 x 1.8 rough-conductor (copper) panel on the room's right wall (x = 1.95), centred at height y.
ShapeDescription roughMetalPanelOnRightWall(float y, float alpha) {
    ShapeDescription panel;
    panel.kind = ShapeDescription::Kind::Rectangle;
    panel.toWorld = Transform::scale(Vec3(0.9f)).then(Transform::rotate(Vec3(0, 1, 0), -90.0f)).then(
        Transform::translate(Vec3(1.95f, y, 0.9f)));  // +z rotated to -x: faces into the room
    panel.bsdf = BsdfDescription{};
    panel.bsdf->kind = BsdfDescription::Kind::RoughConductor;
    panel.bsdf->alphaU = panel.bsdf->alphaV = alpha;
    return panel;
}

}  // namespace

BsdfDescription roughPlastic(const Rgb& reflectance, float alpha, bool twoSided) {
    BsdfDescription bsdf;
    bsdf.kind = BsdfDescription::Kind::RoughPlastic;
    bsdf.reflectance.value = reflectance;
    bsdf.alphaU = bsdf.alphaV = alpha;
    bsdf.twoSided = twoSided;
    return bsdf;
}

SceneDescription roomWithGlossyReflectors(const Rgb& sigmaS, const Rgb& sigmaA, float g) {
    SceneDescription scene = litRoomWithOccluder(sigmaS, sigmaA, g);
    scene.shapes[1].bsdf = roughPlastic(Rgb(0.3f, 0.5f, 0.7f), 0.1f, false);  // the occluder
    scene.shapes.push_back(roughMetalPanelOnRightWall(-0.9f, 0.4f));
    return scene;
}

SceneDescription glassAndMirrorRoom(const Rgb& sigmaS, const Rgb& sigmaA, float g) {
    SceneDescription scene = litRoomWithOccluder(sigmaS, sigmaA, g);
    ShapeDescription glass;
    glass.kind = ShapeDescription::Kind::Sphere;
    glass.center = Vec3(-0.1f, -0.6f, 0.3f);
    glass.radius = 0.55f;
    glass.bsdf = BsdfDescription{};
    glass.bsdf->kind = BsdfDescription::Kind::Dielectric;
    glass.bsdf->intIOR = 1.5f;
    glass.bsdf->extIOR = 1.0f;
    glass.exteriorMedium = 0;  // vacuum inside
    scene.shapes.push_back(glass);
    ShapeDescription mirror;
    mirror.kind = ShapeDescription::Kind::Rectangle;
    mirror.toWorld = Transform::scale(Vec3(0.9f)).then(Transform::rotate(Vec3(0, 1, 0), -90.0f)).then(
        Transform::translate(Vec3(1.95f, -0.2f, 0.9f)));  // +z rotated to -x: faces into the room
    mirror.bsdf = BsdfDescription{};
    mirror.bsdf->kind = BsdfDescription::Kind::Conductor;  // Mitsuba's default: copper
    scene.shapes.push_back(mirror);
    return scene;
}

SceneDescription withoutPointLights(SceneDescription scene) {
    scene.emitters.clear();  // area lights live on their shapes
    return scene;
}

SceneDescription withoutAreaLights(SceneDescription scene) {
    for (ShapeDescription& shape : scene.shapes) shape.areaRadiance.reset();
    return scene;
}

SceneDescription glossyLitRoom(const Rgb& sigmaS, const Rgb& sigmaA, float g, const Rgb& sigmaS2) {
    SceneDescription scene = litRoomWithOccluder(sigmaS, sigmaA, g);
    scene.shapes[0].bsdf = roughPlastic(Rgb(0.6f, 0.55f, 0.5f), 0.1f, true);  // the room
    BsdfDescription plastic;
    plastic.kind = BsdfDescription::Kind::Plastic;
    plastic.reflectance.value = Rgb(0.3f, 0.5f, 0.7f);
    scene.shapes[1].bsdf = plastic;  // the occluder
    scene.shapes[2].toWorld = Transform::scale(Vec3(0.8f)).then(Transform::rotate(Vec3(1, 0, 0), 90.0f)).then(
        Transform::translate(Vec3(-0.8f, 1.95f, 0.8f)));  // a larger light: 1.6 x 1.6
    scene.shapes.push_back(roughMetalPanelOnRightWall(-0.2f, 0.05f));
    scene.media.push_back(medium("haze", sigmaS2, Rgb(0.0f), 0.0f));
    ShapeDescription haze;
    haze.kind = ShapeDescription::Kind::Cube;
    haze.toWorld = Transform::scale(Vec3(0.6f, 0.5f, 0.6f)).then(Transform::translate(Vec3(-0.8f, 0.9f, 0.8f)));
    haze.bsdf = test::nullBsdf();
    haze.interiorMedium = 1;
    haze.exteriorMedium = 0;
    scene.shapes.push_back(haze);
    return scene;
}

SceneDescription glossyFloorUnderAreaLight(float alpha) {
    SceneDescription scene;
    scene.sensor = cameraAtOrigin(16, 12, 60.0f);
    scene.sensor.toWorld = Transform::lookAt(Vec3(0.0f, 1.0f, -2.0f), Vec3(0.0f, 0.0f, 1.0f), Vec3(0, 1, 0));
    ShapeDescription floor;
    floor.kind = ShapeDescription::Kind::Rectangle;
    floor.toWorld = Transform::scale(Vec3(4.0f)).then(Transform::rotate(Vec3(1, 0, 0), -90.0f));  // +z to +y
    floor.bsdf = BsdfDescription{};
    floor.bsdf->kind = BsdfDescription::Kind::RoughConductor;
    floor.bsdf->alphaU = floor.bsdf->alphaV = alpha;
    scene.shapes.push_back(floor);
    ShapeDescription panel;
    panel.kind = ShapeDescription::Kind::Rectangle;
    panel.toWorld = Transform::scale(Vec3(0.6f)).then(Transform::rotate(Vec3(1, 0, 0), 90.0f)).then(
        Transform::translate(Vec3(0.0f, 1.5f, 2.0f)));  // +z to -y: faces the floor
    panel.areaRadiance = Rgb(5.0f, 4.0f, 3.0f);
    panel.bsdf = test::diffuseBsdf(Rgb(0.0f), false);
    scene.shapes.push_back(panel);
    return scene;
}

SceneDescription smallSmokeRoom() {
    SceneDescription scene;
    scene.sensor = cameraAtOrigin(24, 16, 70.0f);
    scene.sensor.toWorld = Transform::lookAt(Vec3(0, 0, -1.8f), Vec3(0, -0.3f, 1), Vec3(0, 1, 0));
    scene.media.push_back(medium("smoke", Rgb(0.3f, 0.35f, 0.4f), Rgb(0.05f), 0.5f));
    scene.sensor.medium = 0;
    ShapeDescription room;
    room.kind = ShapeDescription::Kind::Cube;
    room.toWorld = Transform::scale(Vec3(2.0f));
    room.bsdf = test::diffuseBsdf(Rgb(0.6f, 0.5f, 0.4f), true);
    scene.shapes.push_back(room);
    ShapeDescription ball;
    ball.kind = ShapeDescription::Kind::Sphere;
    ball.center = Vec3(0.5f, -1.4f, 0.8f);
    ball.radius = 0.6f;
    ball.bsdf = test::diffuseBsdf(Rgb(0.2f, 0.6f, 0.3f), false);
    scene.shapes.push_back(ball);
    EmitterDescription spot;
    spot.kind = EmitterDescription::Kind::Spot;
    spot.intensity = Rgb(40.0f);
    spot.cutoffAngle = 30.0f;
    spot.beamWidth = 22.0f;
    spot.toWorld = Transform::lookAt(Vec3(-1.0f, 1.8f, 0.5f), Vec3(0.4f, -2.0f, 0.8f), Vec3(0, 0, 1));
    scene.emitters.push_back(spot);
    return scene;
}

}  // namespace vrl::test
