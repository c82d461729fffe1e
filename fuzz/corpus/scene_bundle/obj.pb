
	scene.xmlÀ
	scene.xml²<scene version="0.5.0">
  <integrator type="volpath"><integer name="maxDepth" value="4"/></integrator>
  <sensor type="perspective">
    <float name="fov" value="45"/>
    <transform name="toWorld"><lookat origin="0, 0, -4" target="0, 0, 0" up="0, 1, 0"/></transform>
    <sampler type="independent"><integer name="sampleCount" value="4"/></sampler>
    <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="12"/></film>
  </sensor>
  <emitter type="point"><point name="position" x="0" y="2" z="-1"/><rgb name="intensity" value="5"/></emitter>

  <shape type="obj"><string name="filename" value="meshes/quad.obj"/><bsdf type="roughplastic"/></shape>
</scene>
k
meshes/quad.objXv 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vt 0 0
vt 1 0
vt 1 1
vn 0 0 1
f 1/1/1 2/2/1 3/3/1 4/1/1
