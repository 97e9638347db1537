// vtk.js side of bench/web-peers: ch2 (raw voxels from the bench's server)
// in a vtkVolume with vtkVolumeMapper (WebGL 2), the bench's transfer
// function, camera and sample distance; frames timed up to a 1-pixel
// read-back (glFinish does not wait in Chrome). Bundled by esbuild (run.sh).
import '@kitware/vtk.js/Rendering/Profiles/Volume';
import vtkGenericRenderWindow from '@kitware/vtk.js/Rendering/Misc/GenericRenderWindow';
import vtkVolume from '@kitware/vtk.js/Rendering/Core/Volume';
import vtkVolumeMapper from '@kitware/vtk.js/Rendering/Core/VolumeMapper';
import vtkImageData from '@kitware/vtk.js/Common/DataModel/ImageData';
import vtkDataArray from '@kitware/vtk.js/Common/Core/DataArray';
import vtkColorTransferFunction from '@kitware/vtk.js/Rendering/Core/ColorTransferFunction';
import vtkPiecewiseFunction from '@kitware/vtk.js/Common/DataModel/PiecewiseFunction';

const SIZE = 512;
let renderWindow, renderer, glWindow, mapper, actor, image;

async function load(url, metaUrl) {
  const meta = await (await fetch(metaUrl)).json();
  const bytes = new Uint8Array(await (await fetch(url)).arrayBuffer());
  image = vtkImageData.newInstance();
  image.setDimensions(meta.dims);
  image.setSpacing(meta.spacing);
  image.setOrigin(meta.origin);
  image.getPointData().setScalars(vtkDataArray.newInstance({ name: 'scalars', numberOfComponents: 1, values: bytes }));

  // The generic window brings the interactor the volume mapper asks
  // whether it is animating (it is not: full quality).
  const generic = vtkGenericRenderWindow.newInstance({ background: [0, 0, 0], listenWindowResize: false });
  generic.setContainer(document.getElementById('view'));
  renderWindow = generic.getRenderWindow();
  renderer = generic.getRenderer();
  glWindow = generic.getApiSpecificRenderWindow();
  glWindow.setSize(SIZE, SIZE);
  mapper = vtkVolumeMapper.newInstance();
  mapper.setInputData(image);
  mapper.setAutoAdjustSampleDistances(false);
  mapper.setMaximumSamplesPerRay(8192);
  actor = vtkVolume.newInstance();
  actor.setMapper(mapper);
  renderer.addVolume(actor);
  renderWindow.render();  // creates the WebGL 2 context
  return meta;
}

// tf: Tessera's TF JSON (x in [0,1] over `window`), step in voxels (1 mm here),
// camera: {position, focalPoint, viewUp, parallelScale}.
function setup({ tf, window: win, step, camera }) {
  const [lo, hi] = win;
  const value = (x) => lo + x * (hi - lo);
  const ctf = vtkColorTransferFunction.newInstance();
  for (const c of tf.color) ctf.addRGBPoint(value(c.x), ...c.rgb);
  const ofun = vtkPiecewiseFunction.newInstance();
  for (const o of tf.opacity) ofun.addPoint(value(o.x), o.alpha);
  const prop = actor.getProperty();
  prop.setRGBTransferFunction(0, ctf);
  prop.setScalarOpacity(0, ofun);
  prop.setScalarOpacityUnitDistance(0, tf.opacity_unit_length || 1);
  prop.setInterpolationTypeToLinear();
  prop.setShade(false);
  const spacing = image.getSpacing();
  mapper.setSampleDistance(step * Math.min(...spacing));
  const cam = renderer.getActiveCamera();
  cam.setParallelProjection(camera.parallelScale > 0);
  if (camera.parallelScale > 0) cam.setParallelScale(camera.parallelScale);
  cam.setViewAngle(camera.viewAngle || 30);
  cam.setFocalPoint(...camera.focalPoint);
  cam.setPosition(...camera.position);
  cam.setViewUp(...camera.viewUp);
  renderer.resetCameraClippingRange();
  renderWindow.render();
  return { sampleDistance: mapper.getSampleDistance() };
}

function context() {
  return glWindow.getContext();
}

function frame() {
  const t0 = performance.now();
  renderWindow.render();
  const g = context();
  const px = new Uint8Array(4);
  g.readPixels(0, 0, 1, 1, g.RGBA, g.UNSIGNED_BYTE, px);
  return performance.now() - t0;
}

function pixels() {
  renderWindow.render();
  const g = context();
  const w = g.drawingBufferWidth, h = g.drawingBufferHeight;
  const px = new Uint8Array(w * h * 4);
  g.readPixels(0, 0, w, h, g.RGBA, g.UNSIGNED_BYTE, px);
  const out = new Uint8Array(px.length);  // top row first
  for (let y = 0; y < h; y++) out.set(px.subarray((h - 1 - y) * w * 4, (h - y) * w * 4), y * w * 4);
  return { width: w, height: h, rgba: out };
}

const params = new URLSearchParams(location.search);
window.peer = {
  name: 'vtk.js',
  ready: load(params.get('raw'), params.get('meta')),
  setup,
  frame,
  pixels,
  info: () => {
    const g = context();
    const dbg = g.getExtension('WEBGL_debug_renderer_info');
    return { version: g.getParameter(g.VERSION), renderer: dbg ? g.getParameter(dbg.UNMASKED_RENDERER_WEBGL) : g.getParameter(g.RENDERER) };
  },
};
