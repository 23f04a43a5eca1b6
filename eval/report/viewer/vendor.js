// What the viewer (viewer.js) takes from npm, bundled into dist/vendor.min.js
// by `npm ci && npm run build` (package-lock.json pins every version).
export * as THREE from "three";
export { OrbitControls } from "three/examples/jsm/controls/OrbitControls.js";
export { PackedSplats, SparkRenderer, SplatMesh } from "@sparkjsdev/spark";
