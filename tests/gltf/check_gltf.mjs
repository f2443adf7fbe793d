// Second reader of godrays' glTF export (tests/cli/test_export_gltf.sh):
//  1. Khronos' glTF-Validator (npm gltf-validator) must report zero errors;
//  2. this script parses the file itself (JSON + .bin or GLB chunks, no glTF library) and checks,
//     at sampled vertices of the water mesh (and of each morph target), the position against
//     the Gerstner surface (seed 000 eq. 5.5.7) evaluated here in double from the wave
//     constants under scenes[0].extras.godrays, within TOL metres, and the normals' length;
//  3. prints the camera and sun node transforms as JSON on stdout for the shell test.
// usage: node check_gltf.mjs VALIDATOR_DIR FILE.gltf|FILE.glb [TOL]
import { readFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import path from 'node:path';

const [validatorDir, file, tolArg] = process.argv.slice(2);
const TOL = tolArg ? Number(tolArg) : 1e-5;
const require = createRequire(path.join(path.resolve(validatorDir), 'node_modules', 'x.js'));
const validator = require('gltf-validator');

function fail(msg) { console.error(`check_gltf: ${file}: ${msg}`); process.exit(1); }

const bytes = new Uint8Array(readFileSync(file));
const report = await validator.validateBytes(bytes, {
  uri: path.basename(file),
  maxIssues: 100,
  externalResourceFunction: (uri) => new Promise((resolve, reject) => {
    try { resolve(new Uint8Array(readFileSync(path.join(path.dirname(file), decodeURIComponent(uri))))); }
    catch (e) { reject(e.toString()); }
  }),
});
const iss = report.issues;
console.error(`check_gltf: validator ${report.validatorVersion}: ${iss.numErrors} errors, ${iss.numWarnings} ` +
              `warnings, ${iss.numInfos} infos, ${iss.numHints} hints`);
for (const m of iss.messages) if (m.severity <= 1) console.error(`  [${m.severity}] ${m.code} ${m.pointer ?? ''}: ${m.message}`);
if (iss.numErrors !== 0) fail(`${iss.numErrors} validator errors`);

// --- our own minimal reader ---
let gltf, bin;
const dv = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
if (dv.getUint32(0, true) === 0x46546c67) { // GLB
  const jlen = dv.getUint32(12, true);
  gltf = JSON.parse(new TextDecoder().decode(bytes.subarray(20, 20 + jlen)));
  const blen = dv.getUint32(20 + jlen, true);
  bin = bytes.subarray(28 + jlen, 28 + jlen + blen);
} else {
  gltf = JSON.parse(new TextDecoder().decode(bytes));
  bin = new Uint8Array(readFileSync(path.join(path.dirname(file), decodeURIComponent(gltf.buffers[0].uri))));
}
function floats(acc) {
  const a = gltf.accessors[acc], v = gltf.bufferViews[a.bufferView];
  const ncomp = { SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4 }[a.type];
  if (a.componentType !== 5126) fail(`accessor ${acc} is not float`);
  const off = bin.byteOffset + (v.byteOffset ?? 0) + (a.byteOffset ?? 0);
  return new Float32Array(bin.buffer.slice(off, off + a.count * ncomp * 4));
}

const x = gltf.scenes[0].extras.godrays;
const W = x.water, M = x.water_mesh;
const node = gltf.nodes[M.node];
const mesh = gltf.meshes[node.mesh], prim = mesh.primitives[0];
const N = M.cells, n1 = N + 1, h = 2 * M.half_size_m / N;
const [cx, cz] = M.rest_centre_xz_m;
if (gltf.accessors[prim.attributes.POSITION].count !== n1 * n1) fail('water vertex count is not (cells + 1)^2');

// seed 000 eq. 5.5.7, from the extras' constants
function gerstner(x0, z0, t) {
  let X = x0, Y = W.rest_height_m, Z = z0;
  for (const w of W.waves) {
    const ph = w.k_per_m * (w.dir_xz[0] * x0 + w.dir_xz[1] * z0) - w.omega_rad_s * t + w.phase_rad;
    X -= w.amplitude_m * w.dir_xz[0] * Math.sin(ph);
    Z -= w.amplitude_m * w.dir_xz[1] * Math.sin(ph);
    Y += w.amplitude_m * Math.cos(ph);
  }
  return [X, Y, Z];
}

const base = floats(prim.attributes.POSITION), bnrm = floats(prim.attributes.NORMAL);
const T = node.translation;
const frames = [{ t: x.time_s, pos: base, nrm: bnrm }];
(prim.targets ?? []).forEach((tg, f) => {
  const dp = floats(tg.POSITION), dn = floats(tg.NORMAL);
  const pos = new Float32Array(base.length), nrm = new Float32Array(base.length);
  for (let k = 0; k < base.length; k++) { pos[k] = base[k] + dp[k]; nrm[k] = bnrm[k] + dn[k]; }
  frames.push({ t: x.frames.water_times_s[f], pos, nrm });
});
if (x.frames && frames.length - 1 !== x.frames.water_times_s.length) fail('morph target count != frame count');

let worst = 0, checked = 0, worstN = 0;
const step = Math.max(1, Math.floor(N / 24));
for (const fr of frames)
  for (let j = 0; j <= N; j += step)
    for (let i = 0; i <= N; i += step) {
      const v = j * n1 + i;
      const want = gerstner(cx - M.half_size_m + i * h, cz - M.half_size_m + j * h, fr.t);
      for (let k = 0; k < 3; k++) worst = Math.max(worst, Math.abs(T[k] + fr.pos[3 * v + k] - want[k]));
      const len = Math.hypot(fr.nrm[3 * v], fr.nrm[3 * v + 1], fr.nrm[3 * v + 2]);
      worstN = Math.max(worstN, Math.abs(len - 1));
      if (!(fr.nrm[3 * v + 1] > 0)) fail(`normal of vertex ${v} does not point up`);
      checked++;
    }
console.error(`check_gltf: ${checked} sampled vertices over ${frames.length} frame(s): max |position - Gerstner| = ` +
              `${worst.toExponential(3)} m (tolerance ${TOL}), max ||n| - 1| = ${worstN.toExponential(2)}`);
if (!(worst <= TOL)) fail(`water position differs from the Gerstner surface by ${worst} m > ${TOL}`);
if (!(worstN <= 1e-4)) fail(`normal length off by ${worstN}`);

// camera and sun: the nodes' quaternions turn local -z into the directions that the scene's
// conventions give from its angles (scene.h: azimuth from +z toward +x, pitch/elevation up)
function rotate(q, v) { // q = [x, y, z, w] unit; v' = v + 2 w (u x v) + 2 u x (u x v)
  const [x, y, z, w] = q, cr = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const u = [x, y, z], t = cr(u, v).map((c) => 2 * c), t2 = cr(u, t);
  return [0, 1, 2].map((k) => v[k] + w * t[k] + t2[k]);
}
const rad = Math.PI / 180;
const byName = (n) => gltf.nodes.find((q) => q.name === n);
const cam = byName('camera'), sun = byName('sun');
const C = x.camera, yaw = C.yaw_deg * rad, pitch = C.pitch_deg * rad;
const fwdWant = [Math.cos(pitch) * Math.sin(yaw), Math.sin(pitch), Math.cos(pitch) * Math.cos(yaw)];
const fwd = rotate(cam.rotation, [0, 0, -1]);
const el = x.sun.elevation_deg * rad, az = x.sun.azimuth_deg * rad;
const sunWant = [-Math.cos(el) * Math.sin(az), -Math.sin(el), -Math.cos(el) * Math.cos(az)];
const sdir = rotate(sun.rotation, [0, 0, -1]);
const dmax = (a, b) => Math.max(...a.map((v, k) => Math.abs(v - b[k])));
const camErr = Math.max(dmax(fwd, fwdWant), dmax(cam.translation, C.position_m));
const sunErr = dmax(sdir, sunWant);
const yfovErr = Math.abs(gltf.cameras[cam.camera].perspective.yfov - C.fov_y_deg * rad);
const L = gltf.extensions.KHR_lights_punctual.lights[sun.extensions.KHR_lights_punctual.light];
const irrErr = dmax(L.color.map((c) => c * L.intensity / 683), x.sun.irradiance_W_m2); // lux -> W/m^2
// the camera stays upright: its right vector (local +x) is horizontal (scene.h)
const rightY = Math.abs(rotate(cam.rotation, [1, 0, 0])[1]);
console.error(`check_gltf: camera forward/position error ${camErr.toExponential(2)}, yfov ${yfovErr.toExponential(2)}, ` +
              `right.y ${rightY.toExponential(2)}; sun direction error ${sunErr.toExponential(2)}, irradiance ${irrErr.toExponential(2)}`);
if (!(camErr <= 1e-9 && yfovErr <= 1e-12 && rightY <= 1e-9)) fail('camera node does not match the scene camera');
if (!(sunErr <= 1e-9 && irrErr <= 1e-9 * Math.max(1, ...x.sun.irradiance_W_m2))) fail('sun light does not match the scene sun');
console.log(JSON.stringify({ camera: { translation: cam.translation, rotation: cam.rotation,
                                       yfov: gltf.cameras[cam.camera].perspective.yfov },
                             sun: { rotation: sun.rotation, light: gltf.extensions.KHR_lights_punctual.lights[0] },
                             extras_camera: x.camera, extras_sun: x.sun }));
