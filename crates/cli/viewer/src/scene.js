// The 3-D view: run.glb loaded with three.js's GLTFLoader, every frame applied on the CPU.
//
// Why the CPU and not three.js's GPU morphing: the page must show each frame with smooth
// normals recomputed from that frame's positions (the file's stored normal deltas are optional,
// and blending them does not give the blended shape's normals), and the strain colours, the top
// view and the test hook all need the current positions anyway. Applying a frame is one pass
// over the vertices (base + the one or two targets with a non-zero weight) and
// computeVertexNormals(): well under a millisecond for the 10 000-vertex cloths atelier writes,
// and it keeps the GPU free of one morph texture per target.

import {
  BufferAttribute,
  BufferGeometry,
  Box3,
  Color,
  DirectionalLight,
  DoubleSide,
  DynamicDrawUsage,
  GridHelper,
  HemisphereLight,
  MeshStandardMaterial,
  PerspectiveCamera,
  Scene,
  SRGBColorSpace,
  Vector3,
  WebGLRenderer,
} from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';

/** base64 → ArrayBuffer. */
export function decodeBase64(text) {
  const bin = atob(text);
  const bytes = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) bytes[i] = bin.charCodeAt(i);
  return bytes.buffer;
}

/** A float attribute's values, itemSize per element, as a fresh Float32Array. */
function floats(attr, itemSize = attr.itemSize) {
  const out = new Float32Array(attr.count * itemSize);
  const get = [attr.getX, attr.getY, attr.getZ, attr.getW];
  for (let i = 0; i < attr.count; i++) {
    for (let c = 0; c < itemSize; c++) out[i * itemSize + c] = get[c].call(attr, i);
  }
  return out;
}

/** Where t falls among increasing key times: key i and the fraction a towards key i + 1. */
export function locate(times, t) {
  const n = times.length;
  if (n === 0 || t <= times[0]) return { i: 0, a: 0 };
  if (t >= times[n - 1]) return { i: n - 1, a: 0 };
  let lo = 0;
  let hi = n - 1;
  while (hi - lo > 1) {
    const mid = (lo + hi) >> 1;
    if (times[mid] <= t) lo = mid;
    else hi = mid;
  }
  return { i: lo, a: (t - times[lo]) / (times[lo + 1] - times[lo]) };
}

// Viridis, sampled at nine points (sRGB): the strain-error ramp, dark (none) to yellow (most).
const VIRIDIS = [
  [0.267, 0.005, 0.329], [0.283, 0.141, 0.458], [0.254, 0.265, 0.53], [0.207, 0.372, 0.553],
  [0.164, 0.471, 0.558], [0.128, 0.567, 0.551], [0.135, 0.659, 0.518], [0.267, 0.749, 0.441],
  [0.478, 0.821, 0.318], [0.741, 0.873, 0.15], [0.993, 0.906, 0.144],
];

/** The ramp's sRGB colour at u in [0, 1]. */
export function ramp(u) {
  const x = Math.min(1, Math.max(0, Number.isFinite(u) ? u : 0)) * (VIRIDIS.length - 1);
  const i = Math.min(VIRIDIS.length - 2, Math.floor(x));
  const f = x - i;
  return VIRIDIS[i].map((c, k) => c + f * (VIRIDIS[i + 1][k] - c));
}

/** The ramp as a CSS gradient (for the legend). */
export function rampCss() {
  const stops = VIRIDIS.map((c, i) => {
    const rgb = c.map((v) => Math.round(v * 255)).join(',');
    return `rgb(${rgb}) ${((100 * i) / (VIRIDIS.length - 1)).toFixed(0)}%`;
  });
  return `linear-gradient(to right, ${stops.join(', ')})`;
}

const srgbToLinear = (c) => (c <= 0.04045 ? c / 12.92 : ((c + 0.055) / 1.055) ** 2.4);
const RAMP_LINEAR = Array.from({ length: 256 }, (_, k) => ramp(k / 255).map(srgbToLinear));

/** One part of the run (a glTF node with a mesh): its frames and how to show them. */
class Part {
  constructor(name, mesh) {
    this.name = name;
    this.mesh = mesh;
    this.cloth = false;
    this.times = null; // key times of its weights channel
    this.weights = null; // keys × targets (CUBICSPLINE: 3 × that)
    this.interpolation = 'LINEAR';
    this.deltas = [];
    this.strain = null; // { frames: [Float32Array per kept frame], max }
    this.panelColours = null; // Float32Array n × 3, linear
    this.panelNames = null;
  }

  get count() {
    return this.base.length / 3;
  }

  /** Positions at time t into the position attribute, then smooth normals. */
  apply(t) {
    const pos = this.geometry.attributes.position.array;
    pos.set(this.base);
    if (this.times && this.deltas.length) {
      const { i, a } = locate(this.times, t);
      const T = this.deltas.length;
      const cubic = this.interpolation === 'CUBICSPLINE';
      const stride = cubic ? 3 * T : T;
      const off = cubic ? T : 0;
      for (let j = 0; j < T; j++) {
        let w = this.weights[i * stride + off + j];
        if (this.interpolation !== 'STEP' && a > 0) w += a * (this.weights[(i + 1) * stride + off + j] - w);
        if (Math.abs(w) < 1e-7) continue;
        const d = this.deltas[j];
        for (let k = 0; k < pos.length; k++) pos[k] += w * d[k];
      }
    }
    this.geometry.attributes.position.needsUpdate = true;
    this.geometry.computeVertexNormals();
  }

  /** Strain error per vertex at time t (interpolated between kept frames as the positions are). */
  strainAt(t) {
    const frames = this.strain.frames;
    if (frames.length === 1 || !this.times) return frames[0];
    const { i, a } = locate(this.times, t);
    if (a === 0 || this.interpolation === 'STEP') return frames[i];
    const out = new Float32Array(frames[i].length);
    for (let k = 0; k < out.length; k++) out[k] = frames[i][k] + a * (frames[i + 1][k] - frames[i][k]);
    return out;
  }
}

/**
 * The 3-D view in `canvas`. Call `await load(glbBytes)`; then setTime, setColourMode, …
 * Throws (from the constructor) when WebGL is not available.
 */
export class Viewer {
  constructor(canvas, { onRender } = {}) {
    this.canvas = canvas;
    this.onRender = onRender || (() => {});
    this.renderer = new WebGLRenderer({ canvas, antialias: true });
    this.renderer.outputColorSpace = SRGBColorSpace;
    this.renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
    this.renderer.setClearColor(new Color(0xe9ecf1), 1);
    this.scene = new Scene();
    this.camera = new PerspectiveCamera(35, 1, 0.01, 100);
    this.scene.add(this.camera);
    // Light: sky and ground, a key light that follows the camera (from above, right, behind the
    // viewer), and a weak light from straight above, so that any view is lit and folds show.
    this.scene.add(new HemisphereLight(0xffffff, 0x6f7482, 1.0));
    const key = new DirectionalLight(0xffffff, 1.9);
    key.position.set(0.6, 1.0, 0.4);
    key.target.position.set(0, 0, -1);
    this.camera.add(key, key.target);
    const above = new DirectionalLight(0xffffff, 0.25);
    above.position.set(0.2, 1, 0.3);
    this.scene.add(above);
    this.controls = new OrbitControls(this.camera, canvas);
    this.controls.addEventListener('change', () => this.requestRender());
    this.parts = [];
    this.time = 0;
    this.colourMode = 'plain';
    this.strainScale = 'frame';
    this.pending = false;
  }

  /** Load run.glb (an ArrayBuffer). Rejects with the loader's error when it does not parse. */
  async load(buffer, { kind } = {}) {
    const gltf = await new GLTFLoader().parseAsync(buffer, '');
    const parser = gltf.parser;
    const json = parser.json;
    gltf.scene.updateMatrixWorld(true);
    const accessor = (i) => parser.getDependency('accessor', i);
    const animation = (json.animations || [])[0];
    for (let nodeIndex = 0; nodeIndex < (json.nodes || []).length; nodeIndex++) {
      const nodeDef = json.nodes[nodeIndex];
      if (nodeDef.mesh === undefined) continue;
      const node = await parser.getDependency('node', nodeIndex);
      let mesh = null;
      node.traverse((o) => {
        if (!mesh && o.isMesh) mesh = o;
      });
      if (!mesh) continue;
      const meshDef = json.meshes[nodeDef.mesh];
      const part = new Part(nodeDef.name || meshDef.name || `part ${nodeIndex}`, mesh);
      const source = mesh.geometry;
      part.base = floats(source.attributes.position, 3);
      part.deltas = (source.morphAttributes.position || []).map((a) => floats(a, 3));
      if (source.attributes.color) {
        part.panelColours = floats(source.attributes.color, 3);
        part.panelNames = Array.isArray(meshDef.extras?.panels) ? meshDef.extras.panels.map(String) : null;
        part.panelColourList = meshDef.extras?.panel_colours;
      }
      // The motion: the sampler driving this node's weights.
      const channel = animation?.channels?.find((c) => c.target?.node === nodeIndex && c.target?.path === 'weights');
      if (channel && part.deltas.length) {
        const sampler = animation.samplers[channel.sampler];
        part.times = floats(await accessor(sampler.input), 1);
        part.weights = floats(await accessor(sampler.output), 1);
        part.interpolation = sampler.interpolation || 'LINEAR';
        const per = part.interpolation === 'CUBICSPLINE' ? 3 : 1;
        if (part.weights.length !== per * part.times.length * part.deltas.length) {
          throw new Error(
            `the animation of ${part.name} has ${part.weights.length} weights for ${part.times.length} key times and ${part.deltas.length} morph targets`,
          );
        }
      }
      // Strain error per vertex and kept frame (optional).
      const strain = meshDef.extras?.strain_error;
      if (strain && Array.isArray(strain.accessors)) {
        part.strainSpec = strain;
        part.strainFrames = await Promise.all(strain.accessors.map((i) => accessor(i).then((a) => floats(a, 1))));
      }
      // A fresh geometry without morph attributes: the frames are applied on the CPU.
      const geometry = new BufferGeometry();
      geometry.setIndex(source.index);
      const position = new BufferAttribute(new Float32Array(part.base), 3);
      position.setUsage(DynamicDrawUsage);
      geometry.setAttribute('position', position);
      part.geometry = geometry;
      mesh.geometry = geometry;
      mesh.morphTargetInfluences = undefined;
      mesh.morphTargetDictionary = undefined;
      mesh.frustumCulled = false;
      const original = Array.isArray(mesh.material) ? mesh.material[0] : mesh.material;
      part.plain = original.clone();
      part.plain.vertexColors = false;
      part.doubleSided = original.side === DoubleSide;
      part.vertexColoured = new MeshStandardMaterial({
        color: 0xffffff,
        vertexColors: true,
        roughness: original.roughness ?? 0.9,
        metalness: 0,
        side: original.side,
      });
      mesh.material = part.plain;
      this.parts.push(part);
    }
    if (!this.parts.length) throw new Error('it holds no mesh to show');
    // The cloth: the node named "cloth", else the first animated part, else the first double-sided one.
    const cloth =
      this.parts.find((p) => p.name === 'cloth') ||
      this.parts.find((p) => p.times) ||
      this.parts.find((p) => p.doubleSided) ||
      this.parts[0];
    cloth.cloth = true;
    this.cloth = cloth;
    this.checkStrain(cloth);
    this.scene.add(gltf.scene);

    // Time line: the cloth's kept frames (else every animated part's).
    const all = this.parts.filter((p) => p.times).flatMap((p) => Array.from(p.times));
    this.frameTimes = cloth.times ? Array.from(cloth.times) : [...new Set(all)].sort((a, b) => a - b);
    this.t0 = this.frameTimes.length ? this.frameTimes[0] : 0;
    this.t1 = this.frameTimes.length ? this.frameTimes[this.frameTimes.length - 1] : 0;

    // The view: fitted to the scene at its first and last frames.
    const box = new Box3();
    const points = [];
    for (const t of [this.t0, this.t1]) {
      for (const p of this.parts) p.apply(t);
      gltf.scene.updateMatrixWorld(true);
      for (const p of this.parts) {
        const a = p.geometry.attributes.position.array;
        for (let i = 0; i < a.length; i += 3) {
          const v = new Vector3(a[i], a[i + 1], a[i + 2]).applyMatrix4(p.mesh.matrixWorld);
          box.expandByPoint(v);
          points.push(v);
        }
      }
    }
    this.box = box;
    // The radius that the view fits: the farthest vertex from the box's centre.
    const middle = box.getCenter(new Vector3());
    this.radius = Math.max(1e-3, points.reduce((m, v) => Math.max(m, v.distanceTo(middle)), 0));
    const size = box.getSize(new Vector3());
    const extent = Math.max(size.x, size.z, 1e-3);
    const step = 10 ** Math.floor(Math.log10(extent / 3)); // 0.1 m for a body, 0.01 m for a sample
    const divisions = Math.max(4, Math.min(200, Math.ceil((2 * extent) / step)));
    this.gridStep = step;
    this.grid = new GridHelper(divisions * step, divisions, 0xaab2c0, 0xcfd4dc);
    const centre = box.getCenter(new Vector3());
    this.grid.position.set(centre.x, box.min.y - 0.002 * extent, centre.z);
    this.scene.add(this.grid);
    this.kind = kind;
    this.view('fit');
    this.setTime(this.t1);
  }

  checkStrain(cloth) {
    this.strainNote = null;
    const spec = cloth.strainSpec;
    if (!spec) {
      this.strainNote = 'run.glb holds no strain error per vertex (written by newer atelier versions)';
      return;
    }
    const frames = cloth.strainFrames;
    const keys = cloth.times ? cloth.times.length : 1;
    if (frames.length !== keys || frames.some((f) => f.length !== cloth.count)) {
      this.strainNote = `run.glb's strain error has ${frames.length} frames of ${frames[0]?.length ?? 0} values; the cloth has ${keys} frames of ${cloth.count} vertices`;
      return;
    }
    let max = Number(spec.max);
    if (!(max > 0)) max = Math.max(...frames.map((f) => f.reduce((m, v) => Math.max(m, v), 0)));
    cloth.strain = { frames, max: max > 0 ? max : 1 };
  }

  /** What the colour modes can do: { panel: note|null, strain: note|null } (null: available). */
  colourAvailability() {
    return {
      panel: this.cloth.panelColours ? null : 'run.glb holds no panel colours (COLOR_0) for the cloth',
      strain: this.cloth.strain ? null : this.strainNote,
    };
  }

  /** Panel legend: [{ name, colour: css }] (names from mesh.extras.panels, colours by first appearance). */
  panelLegend() {
    const c = this.cloth.panelColours;
    if (!c) return [];
    const seen = [];
    const key = new Set();
    for (let i = 0; i < c.length && seen.length < 64; i += 3) {
      const k = `${c[i].toFixed(3)},${c[i + 1].toFixed(3)},${c[i + 2].toFixed(3)}`;
      if (!key.has(k)) {
        key.add(k);
        seen.push(new Color(c[i], c[i + 1], c[i + 2]).getStyle());
      }
    }
    const names = this.cloth.panelNames || [];
    // Exact when the file gives each panel's colour (mesh.extras.panel_colours, linear RGB like
    // COLOR_0); else the colours in the order the vertices first show them (panel by panel).
    const given = this.cloth.panelColourList;
    if (names.length && Array.isArray(given) && given.length === names.length) {
      return names.map((name, i) => ({ name, colour: new Color(...given[i].slice(0, 3).map(Number)).getStyle() }));
    }
    // atelier gives panel k the k-th colour of a fixed list, repeating it past the list's end.
    if (names.length && names.length >= seen.length) return names.map((name, i) => ({ name, colour: seen[i % seen.length] }));
    if (names.length) return names.map((name) => ({ name, colour: null }));
    return seen.map((colour, i) => ({ name: `panel ${i + 1}`, colour }));
  }

  setColourMode(mode) {
    const cloth = this.cloth;
    if ((mode === 'panel' && !cloth.panelColours) || (mode === 'strain' && !cloth.strain)) mode = 'plain';
    this.colourMode = mode;
    const g = cloth.geometry;
    if (mode === 'plain') {
      g.deleteAttribute('color');
      cloth.mesh.material = cloth.plain;
    } else {
      if (mode === 'panel') g.setAttribute('color', new BufferAttribute(cloth.panelColours, 3));
      else g.setAttribute('color', new BufferAttribute(new Float32Array(cloth.count * 3), 3));
      cloth.mesh.material = cloth.vertexColoured;
      cloth.vertexColoured.needsUpdate = true;
    }
    this.applyColours();
    this.requestRender();
  }

  applyColours() {
    const cloth = this.cloth;
    if (this.colourMode !== 'strain') return;
    const values = cloth.strainAt(this.time);
    const colour = cloth.geometry.attributes.color;
    const out = colour.array;
    // The ramp spans 0 … the largest value of this frame ('frame') or of the whole run ('run').
    let top = cloth.strain.max;
    if (this.strainScale === 'frame') {
      top = 0;
      for (let v = 0; v < values.length; v++) if (values[v] > top) top = values[v];
      if (!(top > 0)) top = cloth.strain.max;
    }
    this.strainTop = top;
    const scale = 255 / top;
    for (let v = 0; v < values.length; v++) {
      const c = RAMP_LINEAR[Math.min(255, Math.max(0, Math.round(values[v] * scale)))];
      out[3 * v] = c[0];
      out[3 * v + 1] = c[1];
      out[3 * v + 2] = c[2];
    }
    colour.needsUpdate = true;
  }

  setStrainScale(scale) {
    this.strainScale = scale === 'run' ? 'run' : 'frame';
    this.applyColours();
    this.requestRender();
  }

  setTime(t) {
    this.time = Math.min(this.t1, Math.max(this.t0, t));
    for (const p of this.parts) if (p.times || !p.applied) {
      p.apply(this.time);
      p.applied = true;
    }
    this.applyColours();
    this.requestRender();
  }

  /** The current cloth positions (a copy). */
  clothPositions() {
    return new Float32Array(this.cloth.geometry.attributes.position.array);
  }

  setVisible(part, visible) {
    part.mesh.visible = visible;
    this.requestRender();
  }

  setGrid(visible) {
    this.grid.visible = visible;
    this.requestRender();
  }

  /** Camera presets: 'fit' (the starting view), 'front', 'side', 'top'. */
  view(which) {
    const box = this.box;
    const centre = box.getCenter(new Vector3());
    const radius = this.radius;
    let dir;
    if (which === 'front') dir = new Vector3(0, 0.12, 1);
    else if (which === 'side') dir = new Vector3(1, 0.12, 0);
    else if (which === 'top') dir = new Vector3(0, 1, 0.0015);
    else if (this.kind === 'Drape' || this.kind === 'Wet') dir = new Vector3(0.35, 0.75, 1);
    else dir = new Vector3(0.7, 0.3, 1);
    dir.normalize();
    const fov = (this.camera.fov * Math.PI) / 180;
    const aspect = Math.max(this.camera.aspect, 0.3);
    const fit = Math.min(1, aspect); // narrow windows: fit the width
    const distance = (radius / Math.sin(fov / 2) / fit) * 1.02;
    this.camera.near = distance / 100;
    this.camera.far = distance * 100;
    this.camera.position.copy(centre).addScaledVector(dir, distance);
    this.camera.updateProjectionMatrix();
    this.controls.target.copy(centre);
    this.controls.update();
    this.lastView = which;
    this.requestRender();
  }

  resize(width, height) {
    if (width < 1 || height < 1) return;
    this.renderer.setSize(width, height, false);
    this.camera.aspect = width / height;
    this.camera.updateProjectionMatrix();
    this.requestRender();
  }

  requestRender() {
    if (this.pending) return;
    this.pending = true;
    requestAnimationFrame(() => {
      this.pending = false;
      this.renderNow();
    });
  }

  renderNow() {
    this.renderer.render(this.scene, this.camera);
    this.onRender();
  }
}
