// retarget view: a small WebGL player for skeletons and MJCF robots (no dependencies).
// World frame: Z up, metres. Quaternions are [w, x, y, z].
'use strict';
(function () {
  const statusEl = document.getElementById('status');
  function fail(message) {
    statusEl.dataset.state = 'error';
    statusEl.textContent = 'error: ' + message;
    document.title = 'error: ' + message;
  }
  window.addEventListener('error', (e) => fail(e.message + ' (line ' + e.lineno + ')'));
  window.addEventListener('unhandledrejection', (e) => fail(String(e.reason)));

  // ---------- data ----------
  // URL hash: frame=N, paused=1, hide=all (figures off), follow=0, yaw/pitch/dist (camera),
  // height (m: the height the camera looks at, 0.8; 0.05 for the feet)
  const params = new URLSearchParams(location.hash.slice(1));
  function f32(b64) {
    const s = atob(b64);
    const bytes = new Uint8Array(s.length);
    for (let i = 0; i < s.length; i++) bytes[i] = s.charCodeAt(i);
    return new Float32Array(bytes.buffer);
  }
  function i16(b64) {
    const s = atob(b64);
    const bytes = new Uint8Array(s.length);
    for (let i = 0; i < s.length; i++) bytes[i] = s.charCodeAt(i);
    return new Int16Array(bytes.buffer);
  }
  // Components of unit quaternions, stored as round(v * 32767) in int16.
  const unitI16 = (b64) => Float32Array.from(i16(b64), (v) => v / 32767);
  // Point positions: point 0 per frame in float32, the others as int16 offsets of `step` m.
  function pointPositions(fig) {
    const root = f32(fig.root), off = i16(fig.offsets), n = fig.names.length;
    const out = new Float32Array(off.length);
    for (let k = 0; k < off.length; k++) out[k] = root[Math.floor(k / (3 * n)) * 3 + (k % 3)] + off[k] * fig.step;
    return out;
  }

  // ---------- math ----------
  const V = {
    add: (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]],
    sub: (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]],
    scale: (a, s) => [a[0] * s, a[1] * s, a[2] * s],
    dot: (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2],
    cross: (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]],
    norm: (a) => Math.hypot(a[0], a[1], a[2]),
  };
  V.unit = (a) => { const n = V.norm(a); return n > 1e-12 ? V.scale(a, 1 / n) : [0, 0, 1]; };
  const Q = {
    mul: (a, b) => [
      a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
      a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
      a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
      a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ],
    rot: (q, v) => {
      // v + 2w (u × v) + 2 u × (u × v), u = vector part
      const u = [q[1], q[2], q[3]];
      const t = V.scale(V.cross(u, v), 2);
      return V.add(V.add(v, V.scale(t, q[0])), V.cross(u, t));
    },
    normalize: (q) => {
      const n = Math.hypot(q[0], q[1], q[2], q[3]);
      return n > 1e-12 ? [q[0] / n, q[1] / n, q[2] / n, q[3] / n] : [1, 0, 0, 0];
    },
    axisAngle: (axis, angle) => {
      const s = Math.sin(angle / 2);
      return [Math.cos(angle / 2), axis[0] * s, axis[1] * s, axis[2] * s];
    },
    // Rotation taking +Z onto the unit vector d (MuJoCo's mju_quatZ2Vec).
    fromZ: (d) => {
      const c = d[2];
      if (c < -1 + 1e-9) return [0, 1, 0, 0];
      const axis = V.cross([0, 0, 1], d);
      const s = V.norm(axis);
      if (s < 1e-12) return [1, 0, 0, 0];
      return Q.axisAngle(V.scale(axis, 1 / s), Math.atan2(s, c));
    },
  };
  function rotMat(q) {
    const [w, x, y, z] = q;
    return [
      1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y),
      2 * (x * y - w * z), 1 - 2 * (x * x + z * z), 2 * (y * z + w * x),
      2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y),
    ]; // column-major 3×3
  }
  function mul4(a, b) {
    const o = new Float32Array(16);
    for (let c = 0; c < 4; c++)
      for (let r = 0; r < 4; r++)
        o[c * 4 + r] = a[r] * b[c * 4] + a[4 + r] * b[c * 4 + 1] + a[8 + r] * b[c * 4 + 2] + a[12 + r] * b[c * 4 + 3];
    return o;
  }
  function perspective(fovy, aspect, near, far) {
    const f = 1 / Math.tan(fovy / 2), nf = 1 / (near - far);
    return new Float32Array([f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, (far + near) * nf, -1, 0, 0, 2 * far * near * nf, 0]);
  }
  function lookAt(eye, target, up) {
    const z = V.unit(V.sub(eye, target));
    const x = V.unit(V.cross(up, z));
    const y = V.cross(z, x);
    return new Float32Array([x[0], y[0], z[0], 0, x[1], y[1], z[1], 0, x[2], y[2], z[2], 0,
      -V.dot(x, eye), -V.dot(y, eye), -V.dot(z, eye), 1]);
  }

  // ---------- meshes (position + normal, interleaved) ----------
  function sphereMesh(nu, nv) {
    const out = [];
    const pt = (i, j) => {
      const th = (Math.PI * j) / nv, ph = (2 * Math.PI * i) / nu;
      const p = [Math.sin(th) * Math.cos(ph), Math.sin(th) * Math.sin(ph), Math.cos(th)];
      return p.concat(p);
    };
    for (let j = 0; j < nv; j++)
      for (let i = 0; i < nu; i++) {
        const a = pt(i, j), b = pt(i + 1, j), c = pt(i + 1, j + 1), d = pt(i, j + 1);
        out.push(...a, ...d, ...c, ...a, ...c, ...b);
      }
    return out;
  }
  function cylinderMesh(n) {
    // radius 1, z from -1 to 1, with caps
    const out = [];
    for (let i = 0; i < n; i++) {
      const a0 = (2 * Math.PI * i) / n, a1 = (2 * Math.PI * (i + 1)) / n;
      const c0 = Math.cos(a0), s0 = Math.sin(a0), c1 = Math.cos(a1), s1 = Math.sin(a1);
      out.push(c0, s0, -1, c0, s0, 0, c1, s1, -1, c1, s1, 0, c1, s1, 1, c1, s1, 0);
      out.push(c0, s0, -1, c0, s0, 0, c1, s1, 1, c1, s1, 0, c0, s0, 1, c0, s0, 0);
      out.push(0, 0, 1, 0, 0, 1, c0, s0, 1, 0, 0, 1, c1, s1, 1, 0, 0, 1);
      out.push(0, 0, -1, 0, 0, -1, c1, s1, -1, 0, 0, -1, c0, s0, -1, 0, 0, -1);
    }
    return out;
  }
  function boxMesh() {
    const out = [];
    const faces = [[0, 1, 2], [1, 2, 0], [2, 0, 1]];
    for (const [a, b, c] of faces)
      for (const s of [1, -1]) {
        const corner = (u, v) => {
          const p = [0, 0, 0], n = [0, 0, 0];
          p[a] = s; p[b] = u * s; p[c] = v; n[a] = s;
          return p.concat(n);
        };
        out.push(...corner(-1, -1), ...corner(1, -1), ...corner(1, 1));
        out.push(...corner(-1, -1), ...corner(1, 1), ...corner(-1, 1));
      }
    return out;
  }

  // ---------- renderer ----------
  const LIT_VS = 'attribute vec3 p; attribute vec3 n; uniform mat4 M; uniform mat4 VP; uniform mat3 N;' +
    'varying vec3 vn; void main() { vn = N * n; gl_Position = VP * M * vec4(p, 1.0); }';
  const LIT_FS = 'precision mediump float; varying vec3 vn; uniform vec3 color;' +
    'void main() { vec3 m = normalize(vn);' +
    ' float d = 0.42 + 0.5 * max(dot(m, normalize(vec3(0.35, 0.45, 0.85))), 0.0)' +
    ' + 0.3 * max(dot(m, normalize(vec3(-0.6, -0.5, 0.3))), 0.0);' +
    ' gl_FragColor = vec4(color * d, 1.0); }';
  const LINE_VS = 'attribute vec3 p; attribute vec3 c; uniform mat4 M; uniform mat4 VP; varying vec3 vc;' +
    'void main() { vc = c; gl_Position = VP * M * vec4(p, 1.0); }';
  const LINE_FS = 'precision mediump float; varying vec3 vc; void main() { gl_FragColor = vec4(vc, 1.0); }';

  function makeRenderer(canvas) {
    const gl = canvas.getContext('webgl', { antialias: true, preserveDrawingBuffer: true }) ||
      canvas.getContext('experimental-webgl', { preserveDrawingBuffer: true });
    if (!gl) throw new Error('WebGL is not available in this browser');
    function program(vs, fs) {
      const p = gl.createProgram();
      for (const [type, src] of [[gl.VERTEX_SHADER, vs], [gl.FRAGMENT_SHADER, fs]]) {
        const s = gl.createShader(type);
        gl.shaderSource(s, src);
        gl.compileShader(s);
        if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error('shader: ' + gl.getShaderInfoLog(s));
        gl.attachShader(p, s);
      }
      gl.linkProgram(p);
      if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error('link: ' + gl.getProgramInfoLog(p));
      const loc = (name) => gl.getUniformLocation(p, name);
      return { p, a0: gl.getAttribLocation(p, 'p'), a1: gl.getAttribLocation(p, vs === LIT_VS ? 'n' : 'c'),
        M: loc('M'), VP: loc('VP'), N: loc('N'), color: loc('color') };
    }
    function buffer(data) {
      const b = gl.createBuffer();
      gl.bindBuffer(gl.ARRAY_BUFFER, b);
      gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(data), gl.STATIC_DRAW);
      return { b, count: data.length / 6 };
    }
    const lit = program(LIT_VS, LIT_FS), line = program(LINE_VS, LINE_FS);
    const meshes = { sphere: buffer(sphereMesh(16, 10)), cylinder: buffer(cylinderMesh(16)), box: buffer(boxMesh()) };
    let current = null;
    function use(prog, mesh) {
      if (current !== prog) { gl.useProgram(prog.p); current = prog; }
      gl.bindBuffer(gl.ARRAY_BUFFER, mesh.b);
      gl.enableVertexAttribArray(prog.a0);
      gl.vertexAttribPointer(prog.a0, 3, gl.FLOAT, false, 24, 0);
      gl.enableVertexAttribArray(prog.a1);
      gl.vertexAttribPointer(prog.a1, 3, gl.FLOAT, false, 24, 12);
    }
    return {
      gl,
      lineBuffer: buffer,
      begin(viewProj) {
        const w = canvas.clientWidth, h = canvas.clientHeight, dpr = window.devicePixelRatio || 1;
        if (canvas.width !== Math.round(w * dpr) || canvas.height !== Math.round(h * dpr)) {
          canvas.width = Math.round(w * dpr); canvas.height = Math.round(h * dpr);
        }
        gl.viewport(0, 0, canvas.width, canvas.height);
        gl.clearColor(0.875, 0.894, 0.918, 1);
        gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
        gl.enable(gl.DEPTH_TEST);
        current = null;
        for (const prog of [lit, line]) { gl.useProgram(prog.p); gl.uniformMatrix4fv(prog.VP, false, viewProj); }
      },
      // A mesh at pos/quat with per-axis scale s.
      draw(kind, pos, quat, s, color) {
        use(lit, meshes[kind]);
        const R = rotMat(quat);
        const M = new Float32Array([R[0] * s[0], R[1] * s[0], R[2] * s[0], 0, R[3] * s[1], R[4] * s[1], R[5] * s[1], 0,
          R[6] * s[2], R[7] * s[2], R[8] * s[2], 0, pos[0], pos[1], pos[2], 1]);
        const N = new Float32Array([R[0] / s[0], R[1] / s[0], R[2] / s[0], R[3] / s[1], R[4] / s[1], R[5] / s[1],
          R[6] / s[2], R[7] / s[2], R[8] / s[2]]);
        gl.uniformMatrix4fv(lit.M, false, M);
        gl.uniformMatrix3fv(lit.N, false, N);
        gl.uniform3fv(lit.color, color);
        gl.drawArrays(gl.TRIANGLES, 0, meshes[kind].count);
      },
      bone(a, b, r, color) {
        const d = V.sub(b, a), len = V.norm(d);
        if (len < 1e-6) return;
        this.draw('cylinder', V.scale(V.add(a, b), 0.5), Q.fromZ(V.scale(d, 1 / len)), [r, r, len / 2], color);
      },
      lines(buf, pos, quat, s) {
        use(line, buf);
        const R = rotMat(quat);
        gl.uniformMatrix4fv(line.M, false, new Float32Array([R[0] * s, R[1] * s, R[2] * s, 0, R[3] * s, R[4] * s,
          R[5] * s, 0, R[6] * s, R[7] * s, R[8] * s, 0, pos[0], pos[1], pos[2], 1]));
        gl.drawArrays(gl.LINES, 0, buf.count);
      },
    };
  }

  // ---------- robot forward kinematics (MuJoCo's mj_kinematics) ----------
  function robotKinematics(robot, qposAll, numFrames) {
    const nb = robot.bodies.length, nq = robot.nq;
    const xpos = new Float32Array(numFrames * nb * 3), xquat = new Float32Array(numFrames * nb * 4);
    const jointsOf = robot.bodies.map(() => []);
    robot.joints.forEach((j) => jointsOf[j.body].push(j));
    const P = new Array(nb), R = new Array(nb);
    for (let f = 0; f < numFrames; f++) {
      const q = qposAll.subarray(f * nq, (f + 1) * nq);
      for (let b = 0; b < nb; b++) {
        const body = robot.bodies[b];
        const pp = body.parent === null ? [0, 0, 0] : P[body.parent];
        const pq = body.parent === null ? [1, 0, 0, 0] : R[body.parent];
        let pos = V.add(pp, Q.rot(pq, body.pos)), quat = Q.mul(pq, body.quat);
        for (const j of jointsOf[b]) {
          const a = j.qpos_adr;
          if (j.kind === 'free') {
            pos = [q[a], q[a + 1], q[a + 2]];
            quat = Q.normalize([q[a + 3], q[a + 4], q[a + 5], q[a + 6]]);
          } else if (j.kind === 'slide') {
            pos = V.add(pos, V.scale(Q.rot(quat, j.axis), q[a] - robot.qpos0[a]));
          } else {
            const anchor = V.add(Q.rot(quat, j.pos), pos);
            const local = j.kind === 'ball' ? Q.normalize([q[a], q[a + 1], q[a + 2], q[a + 3]])
              : Q.axisAngle(j.axis, q[a] - robot.qpos0[a]);
            quat = Q.mul(quat, local);
            pos = V.sub(anchor, Q.rot(quat, j.pos));
          }
        }
        P[b] = pos; R[b] = Q.normalize(quat);
        xpos.set(P[b], (f * nb + b) * 3);
        xquat.set(R[b], (f * nb + b) * 4);
      }
    }
    return { xpos, xquat, nb };
  }

  // ---------- scene ----------
  const scene = JSON.parse(document.getElementById('scene').textContent);
  const N = Math.max(1, scene.num_frames);
  const figures = [];
  const toggles = document.getElementById('toggles');
  function toggle(label, checked) {
    const l = document.createElement('label');
    const box = document.createElement('input');
    box.type = 'checkbox'; box.checked = checked && params.get('hide') !== 'all';
    l.append(box, ' ' + label);
    toggles.append(l);
    return box;
  }

  let robot = null;
  if (scene.robot) {
    const r = scene.robot;
    const qpos = f32(r.qpos);
    const k = robotKinematics(r, qpos, N);
    const at = (f, b) => [k.xpos[(f * k.nb + b) * 3], k.xpos[(f * k.nb + b) * 3 + 1], k.xpos[(f * k.nb + b) * 3 + 2]];
    const rotAt = (f, b) => Array.from(k.xquat.subarray((f * k.nb + b) * 4, (f * k.nb + b) * 4 + 4));
    for (const [frame, expected] of r.check) {
      let worst = 0;
      expected.forEach((p, b) => { worst = Math.max(worst, V.norm(V.sub(at(frame, b), p))); });
      if (!(worst < 1e-4)) throw new Error('robot kinematics disagree with the reference at frame ' + frame + ' by ' + worst + ' m');
    }
    const shown = toggle(r.label, true);
    const boneColor = [0.45, 0.56, 0.76], geomColor = [0.7, 0.78, 0.92];
    const hasGeoms = new Set(r.geoms.map((g) => g.body));
    robot = {
      r, qpos, at, rotAt, names: r.bodies.map((b) => b.name), feet: r.feet, label: r.label,
      draw(ren, f) {
        if (!shown.checked) return;
        r.bodies.forEach((b, i) => {
          const p = at(f, i);
          if (b.parent !== null) ren.bone(at(f, b.parent), p, 0.018, boneColor);
          if (!hasGeoms.has(i)) ren.draw('sphere', p, [1, 0, 0, 0], [0.026, 0.026, 0.026], boneColor);
        });
        for (const g of r.geoms) {
          const bp = at(f, g.body), bq = rotAt(f, g.body);
          const p = V.add(bp, Q.rot(bq, g.pos)), q = Q.mul(bq, g.quat), s = g.size;
          if (g.shape === 'sphere') ren.draw('sphere', p, q, [s[0], s[0], s[0]], geomColor);
          else if (g.shape === 'ellipsoid') ren.draw('sphere', p, q, s, geomColor);
          else if (g.shape === 'box') ren.draw('box', p, q, s, geomColor);
          else {
            ren.draw('cylinder', p, q, [s[0], s[0], s[1]], geomColor);
            if (g.shape === 'capsule')
              for (const e of [1, -1]) ren.draw('sphere', V.add(p, Q.rot(q, [0, 0, e * s[1]])), q, [s[0], s[0], s[0]], geomColor);
          }
        }
      },
    };
    figures.push(robot);
  }

  const axesBuf = [];
  for (const fig of scene.skeletons) {
    const pos = pointPositions(fig), rot = fig.orientations ? unitI16(fig.orientations) : new Float32Array(0);
    const n = fig.names.length;
    const at = (f, i) => [pos[(f * n + i) * 3], pos[(f * n + i) * 3 + 1], pos[(f * n + i) * 3 + 2]];
    const rotAt = (f, i) => Array.from(rot.subarray((f * n + i) * 4, (f * n + i) * 4 + 4));
    const shown = toggle(fig.label, true);
    const axes = fig.style === 'targets' && rot.length ? toggle(fig.label + ' frames', true) : null;
    const dark = fig.color.map((c) => c * 0.85);
    figures.push({
      names: fig.names, feet: fig.feet, label: fig.label, at, targets: fig.style === 'targets',
      draw(ren, f) {
        if (!shown.checked) return;
        for (let i = 0; i < n; i++) {
          const p = at(f, i), parent = fig.parents[i];
          if (fig.style === 'skeleton') {
            if (parent !== null) ren.bone(at(f, parent), p, 0.014, dark);
            ren.draw('sphere', p, [1, 0, 0, 0], [0.022, 0.022, 0.022], fig.color);
          } else {
            ren.draw('sphere', p, [1, 0, 0, 0], [0.02, 0.02, 0.02], fig.color);
            if (axes && axes.checked) axesBuf.push([p, rotAt(f, i)]);
          }
        }
      },
    });
  }
  if (!figures.length) throw new Error('nothing to draw');
  const main = figures[0];

  // ---------- overlay ----------
  document.getElementById('file').textContent = scene.title;
  document.getElementById('info').textContent = scene.info.map(([k, v]) => k + ': ' + v).join('\n');
  document.getElementById('info').style.whiteSpace = 'pre';
  document.getElementById('tree').textContent = scene.tree || '';
  const frameInfo = document.getElementById('frameinfo');
  frameInfo.style.whiteSpace = 'pre';

  // ---------- plots ----------
  const plotsEl = document.getElementById('plots');
  const cursors = [];
  const COLORS = ['#1f77b4', '#ff7f0e', '#2ca02c', '#d62728', '#9467bd', '#8c564b', '#e377c2', '#7f7f7f', '#bcbd22', '#17becf'];
  function svgEl(name, attrs, parent) {
    const e = document.createElementNS('http://www.w3.org/2000/svg', name);
    for (const k in attrs) e.setAttribute(k, attrs[k]);
    if (parent) parent.appendChild(e);
    return e;
  }
  function heading(text) { const h = document.createElement('h3'); h.textContent = text; plotsEl.append(h); }
  function addPlot(p, wide) {
    const rows = p.series.length > 1 ? Math.ceil(p.series.length / 5) : 0;
    const W = wide ? 940 : 300, H = (wide ? 150 : 110) + 10 * rows, L = 44, Rm = 6, T = 16, B = 14 + 10 * rows;
    const svg = svgEl('svg', { width: W, height: H, class: 'plot' });
    svgEl('text', { x: L, y: 11, class: 'title' }, svg).textContent = p.title + (p.unit ? ' (' + p.unit + ')' : '');
    let lo = Infinity, hi = -Infinity;
    for (const s of p.series) for (const v of s.values) if (Number.isFinite(v)) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
    if (p.limits) { lo = Math.min(lo, p.limits[0]); hi = Math.max(hi, p.limits[1]); }
    if (!(hi > lo)) { lo = (Number.isFinite(lo) ? lo : 0) - 1; hi = lo + 2; }
    const pad = (hi - lo) * 0.06; lo -= pad; hi += pad;
    const X = (f) => L + ((W - L - Rm) * f) / Math.max(1, N - 1);
    const Y = (v) => T + ((H - T - B) * (hi - v)) / (hi - lo);
    for (const [a, b] of p.shaded) svgEl('rect', { x: X(a), y: T, width: Math.max(0.5, X(b) - X(a)), height: H - T - B, class: 'shade' }, svg);
    if (p.limits) for (const v of p.limits) svgEl('line', { x1: L, x2: W - Rm, y1: Y(v), y2: Y(v), class: 'limit' }, svg);
    svgEl('text', { x: 2, y: T + 8 }, svg).textContent = (hi - pad).toPrecision(3);
    svgEl('text', { x: 2, y: H - B }, svg).textContent = (lo + pad).toPrecision(3);
    svgEl('text', { x: W - Rm, y: H - 3, 'text-anchor': 'end' }, svg).textContent = ((N - 1) / scene.fps).toFixed(1) + ' s';
    p.series.forEach((s, si) => {
      // min/max per pixel column keeps spikes visible with thousands of frames
      const cols = Math.max(1, Math.floor(W - L - Rm)), per = N / cols;
      let d = '';
      for (let c = 0; c < cols; c++) {
        const a = Math.floor(c * per), b = Math.max(a + 1, Math.floor((c + 1) * per));
        let mn = Infinity, mx = -Infinity;
        for (let i = a; i < b && i < N; i++) { const v = s.values[i]; if (Number.isFinite(v)) { mn = Math.min(mn, v); mx = Math.max(mx, v); } }
        if (mn > mx) continue;
        d += (d ? 'L' : 'M') + X(a).toFixed(1) + ' ' + Y(mn).toFixed(1) + 'L' + X(a).toFixed(1) + ' ' + Y(mx).toFixed(1);
      }
      const color = COLORS[si % COLORS.length];
      svgEl('path', { d, stroke: color }, svg);
      if (p.series.length > 1) svgEl('text', { x: L + 4 + (si % 5) * ((W - L - 60) / 5), y: H - 3 - 10 * (rows - 1 - Math.floor(si / 5)), style: 'fill:' + color }, svg).textContent = s.name;
    });
    const cur = svgEl('line', { x1: L, x2: L, y1: T, y2: H - B, class: 'cursor' }, svg);
    cursors.push((f) => { const x = X(f); cur.setAttribute('x1', x); cur.setAttribute('x2', x); });
    svg.addEventListener('click', (e) => {
      const rect = svg.getBoundingClientRect();
      seek(Math.round(((e.clientX - rect.left - L) / (W - L - Rm)) * (N - 1)));
    });
    plotsEl.append(svg);
  }
  const decoded = (p) => ({ ...p, series: p.series.map((s) => ({ name: s.name, values: f32(s.values) })) });
  function series(fn) { const v = new Float32Array(N); for (let f = 0; f < N; f++) v[f] = fn(f); return v; }
  // Contact: foot within 3 cm of its lowest height in the clip and slower than 0.3 m/s.
  function contactPhases(height, speed) {
    let low = Infinity;
    for (const v of height) low = Math.min(low, v);
    const phases = [];
    let start = -1;
    for (let f = 0; f <= N; f++) {
      const on = f < N && height[f] < low + 0.03 && speed[f] < 0.3;
      if (on && start < 0) start = f;
      if (!on && start >= 0) { if (f - start >= 3) phases.push([start, f]); start = -1; }
    }
    return phases;
  }
  function buildPlots() {
    if (scene.plots.length) { heading('From the motion file'); scene.plots.forEach((p) => addPlot(decoded(p), true)); }
    const targets = figures.find((f) => f.targets);
    if (robot && targets) {
      const pairs = targets.names.map((name, i) => [name, i, robot.names.indexOf(name)]).filter((p) => p[2] >= 0);
      if (pairs.length) {
        heading('Tracking error: robot body to IK target');
        addPlot({ title: 'position error per body', unit: 'm', shaded: [], limits: null,
          series: pairs.map(([name, i, b]) => ({ name, values: series((f) => V.norm(V.sub(robot.at(f, b), targets.at(f, i)))) })) }, true);
      }
    }
    heading('Root and feet (' + main.label + ')');
    addPlot({ title: 'root height', unit: 'm', shaded: [], limits: null, series: [{ name: main.names[0], values: series((f) => main.at(f, 0)[2]) }] }, true);
    for (const [side, i] of main.feet) {
      const height = series((f) => main.at(f, i)[2]);
      const speed = series((f) => {
        const a = main.at(Math.max(0, f - 1), i), b = main.at(Math.min(N - 1, f + 1), i);
        const span = Math.min(N - 1, f + 1) - Math.max(0, f - 1);
        return span > 0 ? (Math.hypot(b[0] - a[0], b[1] - a[1]) * scene.fps) / span : 0;
      });
      const shaded = contactPhases(height, speed);
      addPlot({ title: side + ' foot height, contact shaded', unit: 'm', shaded, limits: null, series: [{ name: main.names[i], values: height }] }, true);
      addPlot({ title: side + ' foot horizontal speed', unit: 'm/s', shaded, limits: null, series: [{ name: main.names[i], values: speed }] }, true);
    }
    if (robot) {
      const hinges = robot.r.joints.filter((j) => j.kind === 'hinge' || j.kind === 'slide');
      if (hinges.length) heading('Joint angles against limits');
      for (const j of hinges) {
        addPlot({ title: j.name, unit: j.kind === 'hinge' ? 'rad' : 'm', shaded: [], limits: j.range,
          series: [{ name: j.name, values: series((f) => robot.qpos[f * robot.r.nq + j.qpos_adr]) }] }, false);
      }
    }
  }

  // ---------- camera and playback ----------
  const canvas = document.getElementById('gl');
  const ren = makeRenderer(canvas);
  // 1 m segments: a long line crossing the plane behind the camera may be dropped whole.
  const gridLines = [];
  for (let i = -10; i <= 10; i++) {
    const c = i === 0 ? 0.55 : 0.7;
    for (let j = -10; j < 10; j++)
      gridLines.push(i, j, 0, c, c, c, i, j + 1, 0, c, c, c, j, i, 0, c, c, c, j + 1, i, 0, c, c, c);
  }
  const grid = ren.lineBuffer(gridLines);
  const axes = ren.lineBuffer([0, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0.7, 0, 0, 1, 0, 0, 0.7, 0,
    0, 0, 0, 0, 0, 1, 0, 0, 1, 0, 0, 1]);
  const cam = { yaw: -1.1, pitch: 0.3, dist: 3.6, height: 0.8, target: main.at(0, 0).slice() };
  if (params.has('height')) cam.height = parseFloat(params.get('height')) || 0;
  cam.target[2] = cam.height;
  const state = { frame: 0, playing: true, speed: 1, last: null };
  if (params.has('frame')) state.frame = Math.min(N - 1, Math.max(0, parseInt(params.get('frame'), 10) || 0));
  if (params.get('paused') === '1') state.playing = false;
  for (const k of ['yaw', 'pitch', 'dist']) if (params.has(k)) cam[k] = parseFloat(params.get(k)) || cam[k];

  const $ = (id) => document.getElementById(id);
  const scrub = $('scrub'), playBtn = $('play'), follow = $('follow'), loop = $('loop');
  scrub.max = N - 1;
  if (params.get('follow') === '0') follow.checked = false;
  function seek(f) { state.frame = Math.min(N - 1, Math.max(0, f)); render(); }
  function setPlaying(on) { state.playing = on; state.last = null; playBtn.textContent = on ? 'pause' : 'play'; }
  setPlaying(state.playing);
  playBtn.onclick = () => setPlaying(!state.playing);
  $('prev').onclick = () => { setPlaying(false); seek(Math.round(state.frame) - 1); };
  $('next').onclick = () => { setPlaying(false); seek(Math.round(state.frame) + 1); };
  scrub.oninput = () => seek(parseInt(scrub.value, 10));
  $('speed').onchange = (e) => { state.speed = parseFloat(e.target.value); };
  toggles.onchange = () => render();
  follow.onchange = () => render();
  window.addEventListener('keydown', (e) => {
    if (e.target.tagName === 'SELECT') return;
    const step = e.shiftKey ? 10 : 1;
    if (e.key === ' ') { setPlaying(!state.playing); e.preventDefault(); }
    else if (e.key === 'ArrowRight') { setPlaying(false); seek(Math.round(state.frame) + step); e.preventDefault(); }
    else if (e.key === 'ArrowLeft') { setPlaying(false); seek(Math.round(state.frame) - step); e.preventDefault(); }
    else if (e.key === 'Home') seek(0);
    else if (e.key === 'End') seek(N - 1);
  });
  let drag = null;
  canvas.addEventListener('mousedown', (e) => { drag = [e.clientX, e.clientY]; });
  window.addEventListener('mouseup', () => { drag = null; });
  window.addEventListener('mousemove', (e) => {
    if (!drag) return;
    cam.yaw -= (e.clientX - drag[0]) * 0.008;
    cam.pitch = Math.max(-1.45, Math.min(1.45, cam.pitch + (e.clientY - drag[1]) * 0.008));
    drag = [e.clientX, e.clientY];
    render();
  });
  canvas.addEventListener('wheel', (e) => {
    cam.dist = Math.max(0.3, Math.min(60, cam.dist * Math.exp(e.deltaY * 0.001)));
    e.preventDefault();
    render();
  }, { passive: false });

  function render() {
    const f = Math.round(state.frame);
    if (follow.checked) { const r = main.at(f, 0); cam.target = [r[0], r[1], cam.height]; }
    const cp = Math.cos(cam.pitch);
    const eye = V.add(cam.target, V.scale([cp * Math.cos(cam.yaw), cp * Math.sin(cam.yaw), Math.sin(cam.pitch)], cam.dist));
    const aspect = canvas.clientWidth / Math.max(1, canvas.clientHeight);
    ren.begin(mul4(perspective(0.75, aspect, 0.05, 200), lookAt(eye, cam.target, [0, 0, 1])));
    ren.lines(grid, [Math.round(cam.target[0]), Math.round(cam.target[1]), 0], [1, 0, 0, 0], 1);
    axesBuf.length = 0;
    for (const fig of figures) fig.draw(ren, f);
    for (const [p, q] of axesBuf) ren.lines(axes, p, q, 0.09);
    scrub.value = f;
    frameInfo.textContent = 'frame ' + f + ' / ' + N + '\ntime ' + (f / scene.fps).toFixed(2) + ' s\nFPS ' + +scene.fps.toFixed(3);
    for (const c of cursors) c(f);
  }
  function tick(now) {
    if (state.playing) {
      if (state.last !== null) {
        state.frame += ((now - state.last) / 1000) * scene.fps * state.speed;
        if (state.frame > N - 1) {
          if (loop.checked) state.frame %= N;
          else { state.frame = N - 1; setPlaying(false); }
        }
      }
      state.last = now;
      render();
    }
    requestAnimationFrame(tick);
  }

  buildPlots();
  render();
  requestAnimationFrame(tick);
  if (statusEl.dataset.state !== 'error') {
    statusEl.dataset.state = 'ok';
    statusEl.textContent = 'ok';
    statusEl.dataset.loadMs = Math.round(performance.now());
  }
})();
