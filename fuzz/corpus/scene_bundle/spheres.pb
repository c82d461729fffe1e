
	scene.xml´
	scene.xmlù<scene version="0.5.0">
  <integrator type="volpath"><integer name="maxDepth" value="4"/></integrator>
  <sensor type="perspective">
    <float name="fov" value="45"/>
    <transform name="toWorld"><lookat origin="0, 0, -4" target="0, 0, 0" up="0, 1, 0"/></transform>
    <sampler type="independent"><integer name="sampleCount" value="4"/></sampler>
    <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="12"/></film>
  </sensor>
  <emitter type="point"><point name="position" x="0" y="2" z="-1"/><rgb name="intensity" value="5"/></emitter>

  <medium type="homogeneous" id="fog"><rgb name="sigmaS" value="0.5"/><rgb name="sigmaA" value="0.1"/>
    <phase type="hg"><float name="g" value="0.3"/></phase></medium>
  <shape type="sphere"><float name="radius" value="0.5"/><bsdf type="diffuse"/><ref name="interior" id="fog"/></shape>
  <shape type="rectangle"><transform name="toWorld"><scale value="3"/><translate y="-1"/></transform>
    <emitter type="area"><rgb name="radiance" value="1"/></emitter></shape>
</scene>
