
	scene.xml²
	scene.xml¤<scene version="0.5.0">
  <integrator type="volpath"><integer name="maxDepth" value="4"/></integrator>
  <sensor type="perspective">
    <float name="fov" value="45"/>
    <transform name="toWorld"><lookat origin="0, 0, -4" target="0, 0, 0" up="0, 1, 0"/></transform>
    <sampler type="independent"><integer name="sampleCount" value="4"/></sampler>
    <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="12"/></film>
  </sensor>
  <emitter type="point"><point name="position" x="0" y="2" z="-1"/><rgb name="intensity" value="5"/></emitter>

  <include filename="parts/materials.xml"/>
  <shape type="cube"><ref id="white"/></shape>
</scene>
ƒ
parts/materials.xmll<scene version="0.5.0"><bsdf type="diffuse" id="white"><rgb name="reflectance" value="0.8"/></bsdf></scene>
