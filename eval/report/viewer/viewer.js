// The op2gs report's 3D viewer of one scene (eval/report/viewer.h writes its
// files). Spark renders the Gaussians; this file only decides what they look
// like: the RGB model, or each Gaussian in its object's colour with opacity
// sigma (the baseline's labels) or sigma* (dual opacity).
//
// URL parameters (all optional): mode=rgb|labels|dual|compare, camera=<image
// name>, isolate=<label>, hide=<label,label>. For tests and scripts, with the
// canvas at the camera's size: shots=<shot,shot>&capture=<url> posts, for
// each shot k, the view as PNG to <url><k>.png once it has settled; a shot is
// a mode, or mode@label to isolate that object. log=<url> posts the status
// lines; extract=<label>&without=1&extract_to=<url> posts the object's PLY
// (or the scene's without it) as the download buttons make it.

import { OrbitControls, PackedSplats, SparkRenderer, SplatMesh, THREE } from "../vendor.min.js";

const params = new URLSearchParams(location.search);
const $ = (id) => document.getElementById(id);
// With log=<url>, every status line is also posted there (tests read them).
const setStatus = (text) => {
  $("status").textContent = text;
  if (params.get("log")) fetch(params.get("log"), { method: "POST", body: text });
};

async function fetchOk(url) {
  const response = await fetch(url);
  if (!response.ok) throw new Error(`${url}: ${response.status} ${response.statusText}`);
  return response;
}

// ---- The model: decoded splats, labels and sigma* -------------------------

// Every splat's parameters as Spark decoded them from model.spz, so that the
// label views and hiding objects can rewrite splats without decoding again.
class Splats {
  constructor(packed) {
    const n = packed.numSplats;
    this.n = n;
    this.centers = new Float32Array(3 * n);
    this.scales = new Float32Array(3 * n);
    this.quaternions = new Float32Array(4 * n);
    this.sigma = new Float32Array(n);
    this.colors = new Float32Array(3 * n);
    packed.forEachSplat((i, center, scales, quaternion, opacity, color) => {
      center.toArray(this.centers, 3 * i);
      scales.toArray(this.scales, 3 * i);
      quaternion.toArray(this.quaternions, 4 * i);
      this.sigma[i] = opacity;
      this.colors.set([color.r, color.g, color.b], 3 * i);
    });
  }

  // Writes splat i into packed with this opacity and colour (r, g, b).
  write(packed, i, opacity, r, g, b) {
    const t = Splats.scratch;
    t.center.fromArray(this.centers, 3 * i);
    t.scales.fromArray(this.scales, 3 * i);
    t.quaternion.fromArray(this.quaternions, 4 * i);
    t.color.r = r;
    t.color.g = g;
    t.color.b = b;
    packed.setSplat(i, t.center, t.scales, t.quaternion, opacity, t.color);
  }
}
Splats.scratch = {
  center: new THREE.Vector3(),
  scales: new THREE.Vector3(),
  quaternion: new THREE.Quaternion(),
  color: new THREE.Color(),
};

// gaussians.bin: labels (uint16 little-endian), then sigma* (uint8).
function readLabels(bytes, n) {
  if (bytes.length !== 3 * n) throw new Error(`gaussians.bin holds ${bytes.length} bytes, not ${3 * n}`);
  const labels = new Uint16Array(n);
  const sigmaStar = new Float32Array(n);
  for (let i = 0; i < n; ++i) {
    labels[i] = bytes[2 * i] | (bytes[2 * i + 1] << 8);
    sigmaStar[i] = bytes[2 * n + i] / 255;
  }
  return { labels, sigmaStar };
}

// ---- Views -----------------------------------------------------------------

// One canvas with its renderer; shows one mesh.
class View {
  constructor(container) {
    this.canvas = document.createElement("canvas");
    container.appendChild(this.canvas);
    this.renderer = new THREE.WebGLRenderer({
      canvas: this.canvas,
      antialias: false,
      preserveDrawingBuffer: true,
    });
    this.renderer.setClearColor(0x000000, 1);
    this.scene = new THREE.Scene();
    this.spark = new SparkRenderer({ renderer: this.renderer });
    this.scene.add(this.spark);
    this.mesh = null;
  }

  show(mesh) {
    if (this.mesh === mesh) return;
    if (this.mesh) this.scene.remove(this.mesh);
    this.mesh = mesh;
    if (mesh) this.scene.add(mesh);
  }

  resize(width, height) {
    this.renderer.setPixelRatio(1);
    this.renderer.setSize(width, height, false);
  }

  render(camera) {
    if (this.canvas.style.display !== "none") this.renderer.render(this.scene, camera);
  }
}

// ---- Cameras ----------------------------------------------------------------

// A training or test camera (OpenCV axes: x right, y down, z forward; R, t
// world to camera) as a three.js camera (x right, y up, looking down -z).
function placeCamera(camera, cam) {
  const R = cam.R;
  const t = cam.t;
  const c = [0, 1, 2].map((i) => -(R[i] * t[0] + R[3 + i] * t[1] + R[6 + i] * t[2]));
  const m = new THREE.Matrix4().set(
    R[0], -R[3], -R[6], c[0],
    R[1], -R[4], -R[7], c[1],
    R[2], -R[5], -R[8], c[2],
    0, 0, 0, 1,
  );
  m.decompose(camera.position, camera.quaternion, new THREE.Vector3());
  camera.updateMatrixWorld(true);
}

// The camera's own projection (principal point included), for a canvas of
// exactly its size; otherwise its vertical field of view at the canvas aspect.
function projectCamera(camera, cam, width, height, near, far) {
  camera.near = near;
  camera.far = far;
  if (width === cam.width && height === cam.height) {
    camera.projectionMatrix.makePerspective(
      (-cam.cx * near) / cam.fx,
      ((cam.width - cam.cx) * near) / cam.fx,
      (cam.cy * near) / cam.fy,
      (-(cam.height - cam.cy) * near) / cam.fy,
      near,
      far,
    );
    camera.projectionMatrixInverse.copy(camera.projectionMatrix).invert();
  } else {
    camera.fov = (2 * Math.atan(cam.height / 2 / cam.fy) * 180) / Math.PI;
    camera.aspect = width / height;
    camera.updateProjectionMatrix();
  }
}

// The median depth of the splats in front of the camera: where to orbit.
function orbitTarget(camera, splats) {
  const forward = new THREE.Vector3(0, 0, -1).applyQuaternion(camera.quaternion);
  const depths = [];
  const step = Math.max(1, Math.floor(splats.n / 20000));
  for (let i = 0; i < splats.n; i += step) {
    const d =
      (splats.centers[3 * i] - camera.position.x) * forward.x +
      (splats.centers[3 * i + 1] - camera.position.y) * forward.y +
      (splats.centers[3 * i + 2] - camera.position.z) * forward.z;
    if (d > 0) depths.push(d);
  }
  depths.sort((a, b) => a - b);
  const depth = depths.length ? depths[depths.length >> 1] : 1;
  return camera.position.clone().addScaledVector(forward, depth);
}

// ---- Objects: visibility, picking, PLY extraction ---------------------------

// The Gaussian under a ray: the nearest whose centre lies within twice its
// largest scale of the ray, among the visible ones at least 30% opaque.
function pickGaussian(ray, splats, opacityOf, visible) {
  let best = -1;
  let bestDepth = Infinity;
  const o = ray.origin;
  const d = ray.direction;
  for (let i = 0; i < splats.n; ++i) {
    if (!visible(i) || opacityOf(i) < 0.3) continue;
    const x = splats.centers[3 * i] - o.x;
    const y = splats.centers[3 * i + 1] - o.y;
    const z = splats.centers[3 * i + 2] - o.z;
    const along = x * d.x + y * d.y + z * d.z;
    if (along <= 0 || along >= bestDepth) continue;
    const r = 2 * Math.max(splats.scales[3 * i], splats.scales[3 * i + 1], splats.scales[3 * i + 2]);
    if (x * x + y * y + z * z - along * along < r * r) {
      best = i;
      bestDepth = along;
    }
  }
  return best;
}

const plyTypes = { char: 1, uchar: 1, int8: 1, uint8: 1, short: 2, ushort: 2, int16: 2,
  uint16: 2, int: 4, uint: 4, int32: 4, uint32: 4, float: 4, float32: 4, double: 8, float64: 8 };

// The object's Gaussians (label and sigma* >= the threshold, as
// op2gs-render --ply-object selects them), or with without = true all the
// others, cut from the binary PLY's records: the same bytes the stages wrote.
function cutPly(bytes, label, without, minInstanceOpacity) {
  const headerEnd = new TextDecoder().decode(bytes.subarray(0, 65536)).indexOf("end_header\n");
  if (headerEnd < 0) throw new Error("model.ply has no PLY header");
  const header = new TextDecoder().decode(bytes.subarray(0, headerEnd));
  const start = headerEnd + "end_header\n".length;
  let count = 0;
  let stride = 0;
  const offsets = {};
  for (const line of header.split("\n")) {
    const words = line.trim().split(/\s+/);
    if (words[0] === "element" && words[1] === "vertex") count = Number(words[2]);
    if (words[0] === "property") {
      offsets[words[2]] = { at: stride, type: words[1] };
      stride += plyTypes[words[1]];
    }
  }
  if (!offsets.label) throw new Error("model.ply has no labels");
  const view = new DataView(bytes.buffer, bytes.byteOffset + start);
  const opacity = offsets.instance_opacity || offsets.opacity;
  const keep = [];
  for (let i = 0; i < count; ++i) {
    const l = view.getInt32(i * stride + offsets.label.at, true);
    const logit = view.getFloat32(i * stride + opacity.at, true);
    const member = l === label && 1 / (1 + Math.exp(-logit)) >= minInstanceOpacity;
    if (member !== without) keep.push(i);
  }
  const newHeader = new TextEncoder().encode(
    header.replace(/element vertex \d+/, `element vertex ${keep.length}`) + "end_header\n",
  );
  const out = new Uint8Array(newHeader.length + keep.length * stride);
  out.set(newHeader, 0);
  keep.forEach((i, k) => {
    out.set(bytes.subarray(start + i * stride, start + (i + 1) * stride), newHeader.length + k * stride);
  });
  return out;
}

// Renders until the picture has settled: Spark gathers and sorts the splats
// in the background, a new mesh taking a few frames to show. Settled: Spark
// neither sorting nor due to, and two frames in a row the same picture (at
// least 4 frames, at most 80).
async function settle(views, camera) {
  const gl = views[0].renderer.getContext();
  const { width, height } = views[0].canvas;
  let previous = null;
  let same = 0;
  for (let frame = 0; frame < 80 && same < 2; ++frame) {
    for (const v of views) v.render(camera);
    await new Promise((resolve) => setTimeout(resolve, 200));
    const busy = views.some(
      (v) => v.canvas.style.display !== "none" && (v.spark.sorting || v.spark.sortDirty || v.spark.dirty),
    );
    const pixels = new Uint8Array(4 * width * height);
    gl.readPixels(0, 0, width, height, gl.RGBA, gl.UNSIGNED_BYTE, pixels);
    const unchanged = previous && pixels.every((v, k) => v === previous[k]);
    same = frame >= 3 && !busy && unchanged ? same + 1 : 0;
    previous = pixels;
  }
}

// ---- The page ----------------------------------------------------------------

async function main() {
  const about = await (await fetchOk("scene.json")).json();
  document.title = `op2gs: ${about.name}`;
  $("title").textContent = about.name;
  setStatus(`loading ${about.gaussians.toLocaleString()} Gaussians…`);
  const rgbMesh = new SplatMesh({ url: "model.spz" });
  const [labelBytes] = await Promise.all([
    fetchOk("gaussians.bin").then((r) => r.arrayBuffer()),
    rgbMesh.initialized,
  ]);
  setStatus("decoded");
  const splats = new Splats(rgbMesh.packedSplats);
  setStatus("splats read");
  if (splats.n !== about.gaussians)
    throw new Error(`model.spz holds ${splats.n} Gaussians, scene.json says ${about.gaussians}`);
  const { labels, sigmaStar } = readLabels(new Uint8Array(labelBytes), splats.n);
  const objects = new Map(about.objects.map((o) => [o.label, o]));

  const hidden = new Set();
  const visible = (i) => !hidden.has(labels[i]);
  const labelPacked = {
    labels: new PackedSplats({ maxSplats: splats.n }),
    dual: new PackedSplats({ maxSplats: splats.n }),
  };
  for (const p of Object.values(labelPacked)) p.ensureSplats(splats.n);
  const meshes = {
    rgb: rgbMesh,
    labels: new SplatMesh({ packedSplats: labelPacked.labels }),
    dual: new SplatMesh({ packedSplats: labelPacked.dual }),
  };
  const opacityIn = {
    rgb: (i) => splats.sigma[i],
    labels: (i) => splats.sigma[i],
    dual: (i) => sigmaStar[i],
  };
  // Rewrites every splat of the three meshes for the current visibility.
  function applyVisibility() {
    const rgbPacked = rgbMesh.packedSplats;
    for (let i = 0; i < splats.n; ++i) {
      const shown = visible(i);
      const c = splats.colors;
      splats.write(rgbPacked, i, shown ? splats.sigma[i] : 0, c[3 * i], c[3 * i + 1], c[3 * i + 2]);
      const color = objects.get(labels[i])?.color || [255, 255, 255];
      const [r, g, b] = color.map((v) => v / 255);
      splats.write(labelPacked.labels, i, shown ? splats.sigma[i] : 0, r, g, b);
      splats.write(labelPacked.dual, i, shown ? sigmaStar[i] : 0, r, g, b);
    }
    for (const p of [rgbPacked, labelPacked.labels, labelPacked.dual]) {
      p.numSplats = splats.n;
      p.needsUpdate = true;
    }
    for (const m of Object.values(meshes)) m.updateVersion?.();
  }

  // Views and camera.
  const container = $("views");
  const capture = params.get("capture");
  if (capture) container.classList.add("capture");
  const views = [new View(container), new View(container)];
  const camera = new THREE.PerspectiveCamera();
  const cameras = about.cameras;
  const cameraSelect = $("camera");
  for (const cam of cameras) {
    const option = document.createElement("option");
    option.value = cam.name;
    option.textContent = `${cam.name}${cam.test ? " (test)" : ""}`;
    cameraSelect.appendChild(option);
  }
  // The camera asked for, else the first training view.
  let cam =
    cameras.find((c) => c.name === params.get("camera")) || cameras.find((c) => !c.test) || cameras[0];
  cameraSelect.value = cam.name;
  const extent = splats.n ? new THREE.Box3().setFromArray(splats.centers).getSize(new THREE.Vector3()).length() : 1;
  const controls = new OrbitControls(camera, container);
  let mode = params.get("mode") || "rgb";

  function layout() {
    const compare = mode === "compare";
    views[1].canvas.style.display = compare ? "" : "none";
    let width;
    let height;
    if (capture) {
      width = cam.width;
      height = cam.height;
      for (const v of views) {
        v.canvas.style.width = `${width}px`;
        v.canvas.style.height = `${height}px`;
      }
    } else {
      width = Math.max(1, Math.floor(container.clientWidth / (compare ? 2 : 1)));
      height = Math.max(1, container.clientHeight);
    }
    for (const v of views) v.resize(width, height);
    projectCamera(camera, cam, width, height, extent * 1e-3, extent * 10);
  }
  function useCamera(next) {
    cam = next;
    placeCamera(camera, cam);
    layout();
    controls.target.copy(orbitTarget(camera, splats));
    controls.update();
    placeCamera(camera, cam); // the orbit update keeps the camera where it is; be exact
  }
  function setMode(next) {
    mode = next;
    if (mode === "compare") {
      views[0].show(meshes.labels);
      views[1].show(meshes.dual);
    } else {
      views[0].show(meshes[mode]);
      views[1].show(null);
    }
    for (const input of document.querySelectorAll("input[name=mode]")) input.checked = input.value === mode;
    layout();
  }

  // Objects list.
  function refreshObjects() {
    for (const row of $("objects").children) {
      const label = Number(row.dataset.label);
      row.querySelector("input").checked = !hidden.has(label);
    }
    applyVisibility();
  }
  const describe = (o) =>
    o.label === 0
      ? "background"
      : [...new Set([...(o.name ? [o.name] : []), ...o.queries.map((q) => q.query), ...o.answers])].join(", ") ||
        `object ${o.label}`;
  for (const o of about.objects) {
    const row = document.createElement("div");
    row.dataset.label = o.label;
    row.innerHTML = `<input type="checkbox" checked><span class="swatch"></span><span class="name"></span><button>isolate</button>`;
    row.querySelector(".swatch").style.background = `rgb(${o.color.join(",")})`;
    row.querySelector(".name").textContent = `${o.label}: ${describe(o)}`;
    row.querySelector(".name").title = `${o.gaussians.toLocaleString()} Gaussians`;
    row.querySelector("input").addEventListener("change", (e) => {
      if (e.target.checked) hidden.delete(o.label);
      else hidden.add(o.label);
      refreshObjects();
    });
    row.querySelector("button").addEventListener("click", () => {
      hidden.clear();
      for (const other of about.objects) if (other.label !== o.label) hidden.add(other.label);
      refreshObjects();
    });
    $("objects").appendChild(row);
  }
  $("show-all").addEventListener("click", () => {
    hidden.clear();
    refreshObjects();
  });

  // Picking and downloads.
  let picked = null;
  let plyBytes = null;
  const modelPly = async () => {
    if (!plyBytes) plyBytes = new Uint8Array(await (await fetchOk("model.ply")).arrayBuffer());
    return plyBytes;
  };
  const extract = async (label, without) =>
    cutPly(await modelPly(), label, without, about.min_instance_opacity);
  function showPicked(o) {
    picked = o;
    const lines = [`label ${o.label}: ${describe(o)}`, `${o.gaussians.toLocaleString()} Gaussians`];
    for (const q of o.queries) {
      const f = (v) => (v === undefined ? "–" : (100 * v).toFixed(1));
      lines.push(`"${q.query}": test-view IoU ${f(q["dual-opacity"])} (baseline ${f(q.baseline)})`);
    }
    if (o.answers.length) lines.push(`query mode's answer to: ${o.answers.join(", ")}`);
    $("picked").textContent = lines.join("\n");
    $("download-object").disabled = $("download-without").disabled = o.label === 0;
  }
  async function download(without) {
    const bytes = await extract(picked.label, without);
    const a = document.createElement("a");
    a.href = URL.createObjectURL(new Blob([bytes], { type: "application/octet-stream" }));
    a.download = `${about.name}_${without ? "without_" : ""}object_${picked.label}.ply`;
    a.click();
  }
  $("download-object").addEventListener("click", () => download(false));
  $("download-without").addEventListener("click", () => download(true));
  let downAt = null;
  container.addEventListener("pointerdown", (e) => {
    downAt = [e.clientX, e.clientY];
  });
  container.addEventListener("pointerup", (e) => {
    if (!downAt || Math.hypot(e.clientX - downAt[0], e.clientY - downAt[1]) > 4) return;
    const canvas = e.target.closest("canvas");
    if (!canvas) return;
    const box = canvas.getBoundingClientRect();
    const ndc = new THREE.Vector2(
      ((e.clientX - box.left) / box.width) * 2 - 1,
      -((e.clientY - box.top) / box.height) * 2 + 1,
    );
    const raycaster = new THREE.Raycaster();
    raycaster.setFromCamera(ndc, camera);
    const inDual = mode === "dual" || (mode === "compare" && canvas === views[1].canvas);
    const i = pickGaussian(raycaster.ray, splats, opacityIn[inDual ? "dual" : "labels"], visible);
    if (i >= 0) showPicked(objects.get(labels[i]));
  });

  // Start.
  cameraSelect.addEventListener("change", () => useCamera(cameras.find((c) => c.name === cameraSelect.value)));
  for (const input of document.querySelectorAll("input[name=mode]"))
    input.addEventListener("change", () => setMode(input.value));
  window.addEventListener("resize", layout);
  if (params.get("isolate")) {
    for (const o of about.objects) if (o.label !== Number(params.get("isolate"))) hidden.add(o.label);
  }
  for (const l of (params.get("hide") || "").split(",").filter(Boolean)) hidden.add(Number(l));
  refreshObjects();
  setStatus("visibility applied");
  setMode(mode);
  useCamera(cam);
  setStatus("camera placed");
  await Promise.all(Object.values(meshes).map((m) => m.initialized));
  setStatus(`${splats.n.toLocaleString()} Gaussians, ${about.objects.length - 1} objects`);

  if (params.get("extract_to")) {
    const bytes = await extract(Number(params.get("extract")), params.get("without") === "1");
    await fetch(params.get("extract_to"), { method: "POST", body: bytes });
  }
  if (capture) {
    const shots = (params.get("shots") || mode).split(",");
    for (const [k, shot] of shots.entries()) {
      const [shotMode, isolate] = shot.split("@");
      hidden.clear();
      if (isolate !== undefined)
        for (const o of about.objects) if (o.label !== Number(isolate)) hidden.add(o.label);
      refreshObjects();
      setMode(shotMode);
      await settle(views, camera);
      const png = await new Promise((resolve) => views[0].canvas.toBlob(resolve, "image/png"));
      await fetch(`${capture}${k}.png`, { method: "POST", body: png });
    }
    setStatus("captured");
    return;
  }
  const loop = () => {
    controls.update();
    for (const v of views) v.render(camera);
    requestAnimationFrame(loop);
  };
  loop();
}

main().catch((error) => {
  setStatus(`error: ${error.message}`);
  console.error(error);
  const report = params.get("capture") || params.get("extract_to");
  if (report) fetch(report, { method: "POST", body: `error: ${error.message}` });
});
