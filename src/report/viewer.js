// waam-slicer report viewer: a small hand-written WebGL 1 viewer for the
// data embedded in this page (no library, nothing loaded from the network).
// Part geometry is in the part frame (mm); the cell in the robot base frame
// (mm), where the part is drawn at the pose of the current animation frame.
(function () {
  'use strict';

  // ---- script errors are recorded in the page (and its title) ----
  var errorsEl = document.getElementById('errors');
  var errorCount = 0;
  function recordError(msg) {
    errorCount += 1;
    errorsEl.textContent += msg + '\n';
    document.body.setAttribute('data-errors', String(errorCount));
    if (document.title.indexOf('SCRIPT ERROR') !== 0) document.title = 'SCRIPT ERROR - ' + document.title;
  }
  window.addEventListener('error', function (e) {
    recordError('error: ' + e.message + ' (line ' + (e.lineno || '?') + ':' + (e.colno || '?') + ')');
  });
  window.addEventListener('unhandledrejection', function (e) { recordError('unhandled rejection: ' + e.reason); });
  var consoleError = console.error;
  console.error = function () {
    recordError('console.error: ' + Array.prototype.join.call(arguments, ' '));
    consoleError.apply(console, arguments);
  };

  // Everything the browser fetched for this page (must be nothing).
  function loadedResources() {
    return window.performance && performance.getEntriesByType ?
      performance.getEntriesByType('resource').map(function (e) { return e.name; }) : [];
  }

  // ---- data: base64 of little-endian typed arrays ----
  var littleEndian = new Uint8Array(new Uint32Array([1]).buffer)[0] === 1;
  function bytes(b64) {
    var s = atob(b64), n = s.length, a = new Uint8Array(n);
    for (var i = 0; i < n; i++) a[i] = s.charCodeAt(i);
    return a;
  }
  function f32(b64) {
    var b = bytes(b64), n = b.length >> 2;
    if (littleEndian) return new Float32Array(b.buffer, 0, n);
    var dv = new DataView(b.buffer), out = new Float32Array(n);
    for (var i = 0; i < n; i++) out[i] = dv.getFloat32(4 * i, true);
    return out;
  }
  function u32(b64) {
    var b = bytes(b64), n = b.length >> 2;
    var dv = new DataView(b.buffer), out = new Uint32Array(n);
    for (var i = 0; i < n; i++) out[i] = dv.getUint32(4 * i, true);
    return out;
  }
  function i8(b64) { var b = bytes(b64); return new Int8Array(b.buffer, 0, b.length); }

  var D = JSON.parse(document.getElementById('report-data').textContent);
  var P = D.plan;
  // a fit page: the path is the fitted guide (one layer), FIT holds the mesh
  var FIT = D.fit || null;
  var pos = f32(D.pos), tool = i8(D.tool), nrm = i8(D.normal), bld = i8(D.build);
  var layerStart = u32(D.layer_start);
  var L = D.layer_slice.length, N = pos.length / 3;
  var layerOf = new Float32Array(N);
  for (var l0 = 0; l0 < L; l0++) for (var j0 = layerStart[l0]; j0 < layerStart[l0 + 1]; j0++) layerOf[j0] = l0;
  var fields = D.fields.map(function (f) {
    return { key: f.key, name: f.name, unit: f.unit, diverging: f.diverging, min_half_range: f.min_half_range, data: f32(f.data), mesh: !!f.mesh };
  });
  if (!FIT) fields.push({ key: 'layer', name: 'layer', unit: '', diverging: false, data: layerOf });
  fields.forEach(function (f) {
    var lo = Infinity, hi = -Infinity;
    for (var i = 0; i < f.data.length; i++) {
      var v = f.data[i];
      if (isFinite(v)) { if (v < lo) lo = v; if (v > hi) hi = v; }
    }
    if (!isFinite(lo)) { lo = 0; hi = 0; }
    // a diverging field spans at least ±min_half_range, so that noise
    // around zero is not painted as a full deviation
    if (f.diverging) { var m = Math.max(Math.abs(lo), Math.abs(hi), f.min_half_range || 1e-9); lo = -m; hi = m; }
    if (hi - lo < 1e-12) { hi = lo + 1e-9; }
    f.lo = lo; f.hi = hi;
  });
  var marks = D.marks;
  var markText = {};
  marks.forEach(function (m) { var k = m.layer + ':' + m.point; markText[k] = (markText[k] ? markText[k] + '\n' : '') + m.text; });
  // the layers' corners (orange) and the bead splits on them (cyan)
  var corners = D.corners || [];
  corners.forEach(function (m) { var k = m.layer + ':' + m.point; markText[k] = (markText[k] ? markText[k] + '\n' : '') + m.text; });

  var F = null;
  if (P) {
    F = {
      n: P.frames, layer: u32(P.f_layer), point: u32(P.f_point), time: f32(P.f_time), rz: f32(P.f_rz),
      joints: f32(P.f_joints), chain: f32(P.f_chain), torch: f32(P.f_torch), table: f32(P.f_table), part: f32(P.f_part),
      bodies: f32(P.f_bodies)
    };
  }
  // the whole-cell check's bodies: the moving ones' ends are per frame
  var BODIES = P ? P.bodies : [], movingBodies = 0;
  BODIES.forEach(function (b) { if (b.moving) movingBodies += 1; });
  // the pair to highlight at frame f: the refused collision on its layer,
  // else the layer's closest pair; with the HUD's text
  function closestAt(f) {
    if (!F) return null;
    var li = F.layer[f], c = P.collision;
    if (c && c.layer_index === li) {
      return { names: [c.body_a, c.body_b], collision: true,
        text: 'COLLISION (program refused): ' + c.body_a + '\u2013' + c.body_b + ' ' +
          (c.distance_mm < 0 ? fmt(-c.distance_mm, 1) + ' mm into each other' : fmt(c.distance_mm, 1) + ' mm') +
          ', clearance ' + fmt(c.clearance_mm, 1) + ' mm (' + c.motion + ')' };
    }
    var k = P.closest[li];
    if (k && k.pair) {
      return { names: k.pair, collision: false,
        text: 'closest: ' + k.pair[0] + '\u2013' + k.pair[1] + ' ' + (k.distance_mm === null ? '\u2014' : fmt(k.distance_mm, 1)) + ' mm' };
    }
    return null;
  }

  // ---- colour maps ----
  var SEQ = [[0.267, 0.005, 0.329], [0.229, 0.322, 0.546], [0.128, 0.567, 0.551], [0.369, 0.789, 0.383], [0.993, 0.906, 0.144]];
  var DIV = [[0.230, 0.299, 0.754], [0.552, 0.690, 0.996], [0.865, 0.865, 0.865], [0.958, 0.604, 0.482], [0.706, 0.016, 0.150]];
  var NAN_COLOUR = [0.6, 0.6, 0.6];
  function ramp(stops, t) {
    t = Math.min(1, Math.max(0, t)) * (stops.length - 1);
    var k = Math.min(stops.length - 2, Math.floor(t)), u = t - k, a = stops[k], b = stops[k + 1];
    return [a[0] + (b[0] - a[0]) * u, a[1] + (b[1] - a[1]) * u, a[2] + (b[2] - a[2]) * u];
  }
  function colourOf(f, v) {
    if (!isFinite(v)) return NAN_COLOUR;
    return ramp(f.diverging ? DIV : SEQ, (v - f.lo) / (f.hi - f.lo));
  }
  function fmt(v, d) {
    if (!isFinite(v)) return '—';
    var a = Math.abs(v);
    if (d === undefined) d = a >= 100 ? 1 : a >= 1 ? 3 : 4;
    return v.toFixed(d);
  }

  // ---- panel ----
  var $ = function (id) { return document.getElementById(id); };
  function line(parent, text) { var d = document.createElement('div'); d.textContent = text; parent.appendChild(d); return d; }
  var summary = $('summary');
  if (FIT) {
    var R = FIT.report;
    line(summary, 'tube fitted to ' + FIT.file);
    line(summary, FIT.triangles_total + ' triangles, ' + FIT.vertices_total + ' vertices, ' + R.skins + (R.skins === 1 ? ' skin (mid-surface)' : ' skins (wall)'));
    line(summary, 'guide ' + fmt(R.length_mm, 2) + ' mm through ' + R.guide_points + ' points, ' + R.iterations + ' iterations' + (R.converged ? '' : ' (not converged)'));
    line(summary, 'radius ' + fmt(R.radius_min_mm) + ' to ' + fmt(R.radius_max_mm) + ' mm');
    var fr = line(summary, 'vertices to the fitted surface: RMS ' + fmt(R.rms_mm, 4) + ' mm, max ' + fmt(R.max_mm, 4) + ' mm');
    fr.style.fontWeight = 'bold';
    if (R.surface_to_mesh_max_mm !== null) line(summary, 'fitted surface to the mesh: max ' + fmt(R.surface_to_mesh_max_mm, 4) + ' mm');
    if (R.wall) line(summary, 'wall thickness ' + fmt(R.wall.mean_mm) + ' mm (' + fmt(R.wall.min_mm) + ' to ' + fmt(R.wall.max_mm) + ')');
    if (R.substrate_distance_mm !== null && R.substrate_distance_mm !== undefined) line(summary, 'start end within ' + fmt(R.substrate_distance_mm, 4) + ' mm of the substrate mesh');
    ['show-axes', 'show-wall', 'show-marks'].forEach(function (id) { $(id).parentNode.hidden = true; });
    $('layer-controls').hidden = true;
    $('fit-controls').hidden = false;
  } else {
    line(summary, D.strategy + ' path, Delta = ' + D.delta_mm + ' mm, bead width ' + fmt(D.bead_width_mm) + ' mm');
    line(summary, L + ' layers, ' + D.points_total + ' points, ' + fmt(D.length_mm / 1000, 2) + ' m of bead');
  }
  if (P) {
    line(summary, P.cell_kind + ' cell: ' + P.cell);
    line(summary, 'robot: ' + P.robot);
    var fe = line(summary, P.feasible ? 'plan feasible' : 'plan INFEASIBLE (layers ' + P.infeasible_layers.join(', ') + ')');
    fe.style.fontWeight = 'bold';
    fe.style.color = P.feasible ? '#17692c' : '#b00020';
    if (P.collision) {
      var co = line(summary, 'program REFUSED, collision on layer ' + P.collision.layer + ': ' + P.collision.body_a +
        ' \u2013 ' + P.collision.body_b + ' (' + P.collision.text + ')');
      co.style.fontWeight = 'bold';
      co.style.color = '#b00020';
    }
  }
  D.notes.forEach(function (n) { line($('notes'), n); });
  var fieldSel = $('field');
  fields.forEach(function (f, k) {
    var o = document.createElement('option');
    o.value = String(k);
    o.textContent = f.name + (f.unit ? ' (' + f.unit + ')' : '');
    fieldSel.appendChild(o);
  });
  var loSlider = $('layer-lo'), hiSlider = $('layer-hi');
  loSlider.max = hiSlider.max = String(L - 1);
  hiSlider.value = String(L - 1);
  var state = { field: 0, lo: 0, hi: L - 1, axes: false, wall: false, substrate: true, marks: true,
    cell: !!P, frame: 0, playing: false, speed: 100, clock: 0, only: null, bodies: true, highlight: true,
    mesh: true, tube: true, unlit: false };
  if (marks.length) {
    $('marks-section').hidden = false;
    marks.slice(0, 500).forEach(function (m) {
      var li = document.createElement('li');
      li.textContent = m.text;
      li.addEventListener('click', function () { focusMark(m); });
      $('marks').appendChild(li);
    });
    if (D.marks_total > 500) line($('marks'), '… ' + (D.marks_total - 500) + ' more');
  }

  function drawLegend() {
    var f = fields[state.field], c = $('legend'), g = c.getContext('2d');
    g.clearRect(0, 0, c.width, c.height);
    for (var x = 0; x < 240; x++) {
      var col = ramp(f.diverging ? DIV : SEQ, x / 239);
      g.fillStyle = 'rgb(' + Math.round(255 * col[0]) + ',' + Math.round(255 * col[1]) + ',' + Math.round(255 * col[2]) + ')';
      g.fillRect(10 + x, 4, 1, 16);
    }
    g.fillStyle = '#222'; g.font = '11px sans-serif';
    var labels = [[f.lo, 'left'], [(f.lo + f.hi) / 2, 'center'], [f.hi, 'right']];
    labels.forEach(function (p, k) {
      g.textAlign = p[1];
      g.fillText(f.key === 'layer' ? String(Math.round(p[0])) : fmt(p[0]), [10, 130, 250][k], 34);
    });
    g.textAlign = 'left';
    g.fillStyle = '#666';
    g.fillText((f.unit ? f.unit + ' · ' : '') + 'grey: no value', 10, 45);
  }

  // ---- WebGL ----
  var canvas = $('gl'), overlay = $('overlay');
  var gl = null;
  if (!/nowebgl/.test(location.hash)) {
    try {
      var attrs = { antialias: true, preserveDrawingBuffer: true };
      gl = canvas.getContext('webgl', attrs) || canvas.getContext('experimental-webgl', attrs);
    } catch (e) { gl = null; }
  }
  drawLegend();
  if (!gl) {
    $('nogl').hidden = false;
    document.body.setAttribute('data-webgl', 'none');
    if (/selftest/.test(location.hash)) {
      $('selftest').textContent = JSON.stringify({ webgl: false, nogl_visible: $('nogl').offsetHeight > 0,
        resources: loadedResources() });
      document.body.setAttribute('data-selftest', 'done');
    }
    return;
  }
  document.body.setAttribute('data-webgl', 'ok');

  function shader(type, src) {
    var s = gl.createShader(type);
    gl.shaderSource(s, src);
    gl.compileShader(s);
    if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error('shader: ' + gl.getShaderInfoLog(s));
    return s;
  }
  function program(vs, fs, attribs) {
    var p = gl.createProgram();
    gl.attachShader(p, shader(gl.VERTEX_SHADER, vs));
    gl.attachShader(p, shader(gl.FRAGMENT_SHADER, fs));
    attribs.forEach(function (a, k) { gl.bindAttribLocation(p, k, a); });
    gl.linkProgram(p);
    if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error('program: ' + gl.getProgramInfoLog(p));
    var u = {};
    ['u_mvp', 'u_model', 'u_alpha', 'u_size', 'u_light', 'u_tint'].forEach(function (n) { u[n] = gl.getUniformLocation(p, n); });
    return { p: p, u: u, n: attribs.length };
  }
  var flat = program(
    'attribute vec3 a_pos; attribute vec3 a_col; uniform mat4 u_mvp; uniform float u_size; varying vec3 v_col;' +
    'void main() { gl_Position = u_mvp * vec4(a_pos, 1.0); gl_PointSize = u_size; v_col = a_col; }',
    'precision mediump float; varying vec3 v_col; uniform float u_alpha;' +
    'void main() { gl_FragColor = vec4(v_col, u_alpha); }', ['a_pos', 'a_col']);
  var lit = program(
    'attribute vec3 a_pos; attribute vec3 a_col; attribute vec3 a_nrm; uniform mat4 u_mvp; uniform mat4 u_model;' +
    'varying vec3 v_col; varying vec3 v_n;' +
    'void main() { gl_Position = u_mvp * vec4(a_pos, 1.0); v_n = (u_model * vec4(a_nrm, 0.0)).xyz; v_col = a_col; }',
    'precision mediump float; varying vec3 v_col; varying vec3 v_n; uniform float u_alpha; uniform vec3 u_light;' +
    ' uniform vec4 u_tint;' +
    'void main() { vec3 n = normalize(v_n); float d = abs(dot(n, u_light));' +
    ' gl_FragColor = vec4(mix(v_col, u_tint.rgb, u_tint.a) * (0.35 + 0.65 * d), u_alpha); }', ['a_pos', 'a_col', 'a_nrm']);

  function buffer(data) {
    var b = gl.createBuffer();
    gl.bindBuffer(gl.ARRAY_BUFFER, b);
    gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW);
    return b;
  }
  // A drawable: attribute buffers of 3 floats each (position, colour[, normal]).
  function mesh(arrays) { return { bufs: arrays.map(buffer), count: arrays[0].length / 3 }; }
  function setColours(m, cols) { gl.bindBuffer(gl.ARRAY_BUFFER, m.bufs[1]); gl.bufferData(gl.ARRAY_BUFFER, cols, gl.STATIC_DRAW); }
  function draw(prog, m, mode, first, count, mvp, opts) {
    if (!m || count <= 0) return;
    gl.useProgram(prog.p);
    for (var k = 0; k < prog.n; k++) {
      gl.enableVertexAttribArray(k);
      gl.bindBuffer(gl.ARRAY_BUFFER, m.bufs[k]);
      gl.vertexAttribPointer(k, 3, gl.FLOAT, false, 0, 0);
    }
    gl.uniformMatrix4fv(prog.u.u_mvp, false, mvp);
    gl.uniform1f(prog.u.u_alpha, opts.alpha === undefined ? 1 : opts.alpha);
    if (prog.u.u_size) gl.uniform1f(prog.u.u_size, opts.size || 1);
    if (prog.u.u_model) gl.uniformMatrix4fv(prog.u.u_model, false, opts.model || IDENTITY);
    if (prog.u.u_light) gl.uniform3fv(prog.u.u_light, opts.light || [0, 0, 1]);
    if (prog.u.u_tint) gl.uniform4fv(prog.u.u_tint, opts.tint || [0, 0, 0, 0]);
    gl.drawArrays(mode, first, count);
    for (var a = 0; a < prog.n; a++) gl.disableVertexAttribArray(a);
  }

  // ---- 4×4 matrices, column-major ----
  var IDENTITY = new Float32Array([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]);
  function mul(a, b) {
    var o = new Float32Array(16);
    for (var c = 0; c < 4; c++) for (var r = 0; r < 4; r++) {
      var s = 0;
      for (var k = 0; k < 4; k++) s += a[k * 4 + r] * b[c * 4 + k];
      o[c * 4 + r] = s;
    }
    return o;
  }
  function perspective(fovy, aspect, near, far) {
    var f = 1 / Math.tan(fovy / 2), o = new Float32Array(16);
    o[0] = f / aspect; o[5] = f; o[10] = (far + near) / (near - far); o[11] = -1; o[14] = 2 * far * near / (near - far);
    return o;
  }
  function ortho(s) { var o = new Float32Array(IDENTITY); o[0] = o[5] = 1 / s; o[10] = -1 / s; return o; }
  function sub(a, b) { return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]; }
  function add(a, b) { return [a[0] + b[0], a[1] + b[1], a[2] + b[2]]; }
  function scale(a, s) { return [a[0] * s, a[1] * s, a[2] * s]; }
  function dot(a, b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
  function cross(a, b) { return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]; }
  function norm(a) { return Math.sqrt(dot(a, a)); }
  function unit(a) { var n = norm(a) || 1; return scale(a, 1 / n); }
  function lookAt(eye, target, up) {
    var z = unit(sub(eye, target)), x = unit(cross(up, z)), y = cross(z, x);
    return new Float32Array([x[0], y[0], z[0], 0, x[1], y[1], z[1], 0, x[2], y[2], z[2], 0,
      -dot(x, eye), -dot(y, eye), -dot(z, eye), 1]);
  }
  function apply(m, p) {
    return [m[0] * p[0] + m[4] * p[1] + m[8] * p[2] + m[12], m[1] * p[0] + m[5] * p[1] + m[9] * p[2] + m[13],
      m[2] * p[0] + m[6] * p[1] + m[10] * p[2] + m[14], m[3] * p[0] + m[7] * p[1] + m[11] * p[2] + m[15]];
  }

  // ---- scene geometry (part frame) ----
  var bead = D.bead_width_mm, delta = D.delta_mm;
  function vtx(j) { return [pos[3 * j], pos[3 * j + 1], pos[3 * j + 2]]; }
  function dir(a, j) { return [a[3 * j] / 127, a[3 * j + 1] / 127, a[3 * j + 2] / 127]; }
  // path polylines: one vertex pair per segment, segments of layer l from segStart[l]
  var segSrc = [], segStart = new Uint32Array(L + 1);
  for (var l = 0; l < L; l++) {
    segStart[l] = segSrc.length;
    var a = layerStart[l], b = layerStart[l + 1];
    for (var j = a; j + 1 < b; j++) segSrc.push(j, j + 1);
    if (D.layer_closed[l] && b - a > 2) segSrc.push(b - 1, a);
  }
  segStart[L] = segSrc.length;
  var segPos = new Float32Array(3 * segSrc.length);
  segSrc.forEach(function (s, k) { segPos[3 * k] = pos[3 * s]; segPos[3 * k + 1] = pos[3 * s + 1]; segPos[3 * k + 2] = pos[3 * s + 2]; });
  var pathMesh = mesh([segPos, new Float32Array(segPos.length)]);
  var pointColours = new Float32Array(3 * N);
  var GUIDE_COLOUR = [0.95, 0.95, 0.95], MESH_COLOUR = [0.72, 0.74, 0.78];
  function recolour() {
    var f = fields[state.field];
    if (fitMesh) recolourMesh(f);
    for (var i = 0; i < N; i++) {
      var c = f.mesh ? GUIDE_COLOUR : colourOf(f, f.data[i]);
      pointColours[3 * i] = c[0]; pointColours[3 * i + 1] = c[1]; pointColours[3 * i + 2] = c[2];
    }
    var cols = new Float32Array(segPos.length);
    segSrc.forEach(function (s, k) { cols[3 * k] = pointColours[3 * s]; cols[3 * k + 1] = pointColours[3 * s + 1]; cols[3 * k + 2] = pointColours[3 * s + 2]; });
    setColours(pathMesh, cols);
    drawLegend();
  }
  // tool axes, thinned to about 30 000
  var axisStride = Math.max(1, Math.ceil(N / 30000)), axisLen = 3 * delta;
  var axStart = new Uint32Array(L + 1), axP = [], axC = [];
  for (l = 0; l < L; l++) {
    axStart[l] = axP.length / 3;
    for (j = layerStart[l]; j < layerStart[l + 1]; j += axisStride) {
      var p = vtx(j), t = dir(tool, j);
      axP.push(p[0], p[1], p[2], p[0] + axisLen * t[0], p[1] + axisLen * t[1], p[2] + axisLen * t[2]);
      axC.push(0.75, 0.75, 0.8, 1.0, 0.55, 0.15);
    }
  }
  axStart[L] = axP.length / 3;
  var axesMesh = mesh([new Float32Array(axP), new Float32Array(axC)]);
  if (axisStride > 1) line($('notes'), 'Tool axes: one in ' + axisStride + ' drawn points.');
  // the deposited wall: bead section (±width/2 along the normal, down by the
  // local distance along the build direction) swept along each layer
  var wallStride = Math.max(1, Math.ceil(N / 40000));
  var wStart = new Uint32Array(L + 1), wP = [], wN = [];
  var devField = FIT ? null : fields[0];
  function section(j) {
    var p = vtx(j), n = dir(nrm, j), bd = dir(bld, j), dv = devField ? devField.data[j] : NaN;
    var h = isFinite(dv) ? Math.max(0, Math.min(3 * delta, delta + dv)) : delta;
    var o = scale(n, bead / 2), down = scale(bd, h);
    return { c: [add(p, o), sub(p, o), sub(sub(p, o), down), sub(add(p, o), down)], n: n, b: bd };
  }
  function quad(a, b, c, d, na, nb) {
    [a, b, c, a, c, d].forEach(function (v, k) { wP.push(v[0], v[1], v[2]); var q = (k === 1 || k === 2 || k === 4) ? nb : na; wN.push(q[0], q[1], q[2]); });
  }
  for (l = 0; l < L; l++) {
    wStart[l] = wP.length / 3;
    var idx = [];
    for (j = layerStart[l]; j < layerStart[l + 1]; j += wallStride) idx.push(j);
    if (idx.length && idx[idx.length - 1] !== layerStart[l + 1] - 1) idx.push(layerStart[l + 1] - 1);
    if (D.layer_closed[l] && idx.length > 2) idx.push(idx[0]);
    var prev = null;
    idx.forEach(function (jj) {
      var s = section(jj);
      if (prev) {
        quad(prev.c[0], s.c[0], s.c[3], prev.c[3], prev.n, s.n);
        quad(prev.c[1], s.c[1], s.c[2], prev.c[2], prev.n, s.n);
        quad(prev.c[0], s.c[0], s.c[1], prev.c[1], prev.b, s.b);
      }
      prev = s;
    });
  }
  wStart[L] = wP.length / 3;
  var wallCol = new Float32Array(wP.length);
  for (j = 0; j < wallCol.length; j += 3) { wallCol[j] = 0.78; wallCol[j + 1] = 0.5; wallCol[j + 2] = 0.25; }
  var wallMesh = mesh([new Float32Array(wP), wallCol, new Float32Array(wN)]);
  if (wallStride > 1) line($('notes'), 'Wall: built from one in ' + wallStride + ' drawn points.');
  // substrate
  var subMesh = null;
  if (D.substrate) {
    var sp = f32(D.substrate), sn = new Float32Array(sp.length), sc = new Float32Array(sp.length);
    for (j = 0; j < sp.length; j += 9) {
      var fn = unit(cross(sub([sp[j + 3], sp[j + 4], sp[j + 5]], [sp[j], sp[j + 1], sp[j + 2]]),
        sub([sp[j + 6], sp[j + 7], sp[j + 8]], [sp[j], sp[j + 1], sp[j + 2]])));
      for (var v = 0; v < 9; v += 3) { sn[j + v] = fn[0]; sn[j + v + 1] = fn[1]; sn[j + v + 2] = fn[2]; sc[j + v] = 0.6; sc[j + v + 1] = 0.68; sc[j + v + 2] = 0.8; }
    }
    subMesh = mesh([sp, sc, sn]);
  }
  // the fit: the mesh (one vertex triple per drawn triangle, face normals),
  // coloured per vertex, and the fitted tube
  var fitMesh = null, tubeMesh = null, fitVerts = null, fitCorner = null;
  if (FIT) {
    fitVerts = f32(FIT.vertices);
    fitCorner = u32(FIT.triangles);
    var mp = new Float32Array(3 * fitCorner.length), mn = new Float32Array(3 * fitCorner.length);
    for (j = 0; j < fitCorner.length; j += 3) {
      var c0 = fitCorner[j], c1 = fitCorner[j + 1], c2 = fitCorner[j + 2];
      var q0 = [fitVerts[3 * c0], fitVerts[3 * c0 + 1], fitVerts[3 * c0 + 2]];
      var q1 = [fitVerts[3 * c1], fitVerts[3 * c1 + 1], fitVerts[3 * c1 + 2]];
      var q2 = [fitVerts[3 * c2], fitVerts[3 * c2 + 1], fitVerts[3 * c2 + 2]];
      var fnrm = unit(cross(sub(q1, q0), sub(q2, q0)));
      [q0, q1, q2].forEach(function (q, k) {
        mp.set(q, 3 * (j + k));
        mn.set(fnrm, 3 * (j + k));
      });
    }
    fitMesh = mesh([mp, new Float32Array(mp.length), mn]);
    var tp = f32(FIT.tube), tn = new Float32Array(tp.length), tc = new Float32Array(tp.length);
    for (j = 0; j < tp.length; j += 9) {
      var tf = unit(cross(sub([tp[j + 3], tp[j + 4], tp[j + 5]], [tp[j], tp[j + 1], tp[j + 2]]),
        sub([tp[j + 6], tp[j + 7], tp[j + 8]], [tp[j], tp[j + 1], tp[j + 2]])));
      for (var tv = 0; tv < 9; tv += 3) { tn.set(tf, j + tv); tc[j + tv] = 0.35; tc[j + tv + 1] = 0.85; tc[j + tv + 2] = 0.95; }
    }
    tubeMesh = mesh([tp, tc, tn]);
  }
  function recolourMesh(f) {
    var nv = fitVerts.length / 3, vc = new Float32Array(3 * nv), k;
    for (k = 0; k < nv; k++) {
      var c = f.mesh ? colourOf(f, f.data[k]) : MESH_COLOUR;
      vc[3 * k] = c[0]; vc[3 * k + 1] = c[1]; vc[3 * k + 2] = c[2];
    }
    var cols = new Float32Array(3 * fitCorner.length);
    for (k = 0; k < fitCorner.length; k++) {
      var v = fitCorner[k];
      cols[3 * k] = vc[3 * v]; cols[3 * k + 1] = vc[3 * v + 1]; cols[3 * k + 2] = vc[3 * v + 2];
    }
    setColours(fitMesh, cols);
  }
  // violation marks (rebuilt when the layer range changes)
  var marksMesh = null, cornersMesh = null;
  function rebuildMarks() {
    var mp = [], mc = [];
    marks.forEach(function (m) {
      if (m.layer < state.lo || m.layer > state.hi) return;
      mp.push(m.at[0], m.at[1], m.at[2]); mc.push(1.0, 0.15, 0.2);
    });
    marksMesh = mp.length ? mesh([new Float32Array(mp), new Float32Array(mc)]) : null;
    var cp = [], cc = [];
    corners.forEach(function (m) {
      if (m.layer < state.lo || m.layer > state.hi) return;
      cp.push(m.at[0], m.at[1], m.at[2]);
      if (m.split) cc.push(0.1, 0.8, 1.0); else cc.push(1.0, 0.6, 0.1);
    });
    cornersMesh = cp.length ? mesh([new Float32Array(cp), new Float32Array(cc)]) : null;
  }
  var hoverMesh = null;

  // ---- the cell at a frame (robot base frame) ----
  function frameVec(arr, stride, f, k) { var o = f * stride + 3 * k; return [arr[o], arr[o + 1], arr[o + 2]]; }
  function partModel(f) {
    var o = 12 * f, a = F.part;
    if (!isFinite(a[o])) return null;
    return new Float32Array([a[o], a[o + 1], a[o + 2], 0, a[o + 3], a[o + 4], a[o + 5], 0, a[o + 6], a[o + 7], a[o + 8], 0,
      a[o + 9], a[o + 10], a[o + 11], 1]);
  }
  function cylinder(outP, outC, outN, a, b, r0, r1, col) {
    var d = sub(b, a), len = norm(d);
    if (!(len > 1e-9)) return;
    var z = scale(d, 1 / len), x = unit(cross(Math.abs(z[0]) < 0.9 ? [1, 0, 0] : [0, 1, 0], z)), y = cross(z, x);
    var S = 16;
    function put(p, n) { outP.push(p[0], p[1], p[2]); outC.push(col[0], col[1], col[2]); outN.push(n[0], n[1], n[2]); }
    for (var k = 0; k < S; k++) {
      var t0 = 2 * Math.PI * k / S, t1 = 2 * Math.PI * (k + 1) / S;
      var u0 = add(scale(x, Math.cos(t0)), scale(y, Math.sin(t0))), u1 = add(scale(x, Math.cos(t1)), scale(y, Math.sin(t1)));
      var a0 = add(a, scale(u0, r0)), a1 = add(a, scale(u1, r0)), b0 = add(b, scale(u0, r1)), b1 = add(b, scale(u1, r1));
      put(a0, u0); put(a1, u1); put(b1, u1); put(a0, u0); put(b1, u1); put(b0, u0);
      put(a, scale(z, -1)); put(a1, scale(z, -1)); put(a0, scale(z, -1));
      put(b, z); put(b0, z); put(b1, z);
    }
  }
  function sphere(outP, outC, outN, c, r, col) {
    var S = 12, T = 8;
    function at(i, j) {
      var th = Math.PI * i / T, ph = 2 * Math.PI * j / S;
      return [Math.sin(th) * Math.cos(ph), Math.sin(th) * Math.sin(ph), Math.cos(th)];
    }
    function put(u) { outP.push(c[0] + r * u[0], c[1] + r * u[1], c[2] + r * u[2]); outC.push(col[0], col[1], col[2]); outN.push(u[0], u[1], u[2]); }
    for (var i = 0; i < T; i++) for (var j = 0; j < S; j++) {
      var a = at(i, j), b = at(i + 1, j), cc = at(i + 1, j + 1), d = at(i, j + 1);
      put(a); put(b); put(cc); put(a); put(cc); put(d);
    }
  }
  function boxMesh(outP, outC, outN, lo, hi, col) {
    function put(p, n) { outP.push(p[0], p[1], p[2]); outC.push(col[0], col[1], col[2]); outN.push(n[0], n[1], n[2]); }
    for (var ax = 0; ax < 3; ax++) for (var side = 0; side < 2; side++) {
      var u = (ax + 1) % 3, v = (ax + 2) % 3, n = [0, 0, 0];
      n[ax] = side ? 1 : -1;
      var q = [];
      [[0, 0], [1, 0], [1, 1], [0, 1]].forEach(function (t) {
        var p = [0, 0, 0];
        p[ax] = side ? hi[ax] : lo[ax]; p[u] = t[0] ? hi[u] : lo[u]; p[v] = t[1] ? hi[v] : lo[v];
        q.push(p);
      });
      put(q[0], n); put(q[1], n); put(q[2], n); put(q[0], n); put(q[2], n); put(q[3], n);
    }
  }
  // one body of the check at frame f into the arrays `o` ({p, c, n})
  function bodyAt(f, k, m) {
    var b = BODIES[k];
    if (!b.moving) return [b.a, b.b];
    var o = 6 * (movingBodies * f + m), a = F.bodies;
    return [[a[o], a[o + 1], a[o + 2]], [a[o + 3], a[o + 4], a[o + 5]]];
  }
  function addBody(o, b, ends, col) {
    var a = ends[0], e = ends[1];
    if (!isFinite(a[0]) || !isFinite(e[0])) return;
    if (b.kind === 'box') boxMesh(o.p, o.c, o.n, a, e, col);
    else if (b.kind === 'cylinder') cylinder(o.p, o.c, o.n, a, e, b.radius_mm, b.radius_mm, col);
    else {
      cylinder(o.p, o.c, o.n, a, e, b.radius_mm, b.radius_mm, col);
      sphere(o.p, o.c, o.n, a, b.radius_mm, col);
      sphere(o.p, o.c, o.n, e, b.radius_mm, col);
    }
  }
  var BODY = [0.55, 0.75, 0.95], HIGHLIGHT = [1.0, 0.08, 0.04];
  var bodyMesh = null, hiMesh = null, partHighlighted = false, highlighted = [];
  function buildBodies(f) {
    var plain = { p: [], c: [], n: [] }, hi = { p: [], c: [], n: [] }, cl = closestAt(f), names = cl && state.highlight ? cl.names : [];
    var m = 0;
    highlighted = [];
    BODIES.forEach(function (b, k) {
      var ends = bodyAt(f, k, m);
      if (b.moving) m += 1;
      var h = names.indexOf(b.name) >= 0;
      if (h && highlighted.indexOf(b.name) < 0) highlighted.push(b.name);
      addBody(h ? hi : plain, b, ends, h ? HIGHLIGHT : BODY);
    });
    partHighlighted = names.indexOf(P.part_body) >= 0;
    if (partHighlighted) highlighted.push(P.part_body);
    function mk(o) { return o.p.length ? mesh([new Float32Array(o.p), new Float32Array(o.c), new Float32Array(o.n)]) : null; }
    bodyMesh = mk(plain); hiMesh = mk(hi);
  }
  var cellMesh = null, cellMeshFrame = -1;
  function buildCell(f) {
    var R = P.reach_mm, cp = [], cc = [], cn = [];
    var ROBOT = [0.96, 0.62, 0.12], DARK = [0.25, 0.25, 0.28], STEEL = [0.45, 0.55, 0.7];
    var ch = [];
    for (var k = 0; k < 8; k++) ch.push(frameVec(F.chain, 24, f, k));
    if (isFinite(ch[0][0])) {
      cylinder(cp, cc, cn, [0, 0, -0.02 * R], [0, 0, 0.04 * R], 0.16 * R, 0.16 * R, DARK);
      var radii = [0.1, 0.08, 0.065, 0.05, 0.05, 0.04, 0.012];
      for (k = 0; k < 7; k++) {
        if (k === 6 && P.cell_kind === 'part carried') break;
        cylinder(cp, cc, cn, ch[k], ch[k + 1], radii[k] * R, radii[k] * R, k === 6 ? DARK : ROBOT);
      }
      cylinder(cp, cc, cn, ch[6], add(ch[6], scale(unit(sub(ch[6], ch[5])), 0.015 * R)), 0.045 * R, 0.045 * R, DARK);
    }
    var t0 = frameVec(F.torch, 6, f, 0), t1 = frameVec(F.torch, 6, f, 1);
    if (isFinite(t0[0]) && norm(sub(t1, t0)) > 0) {
      var tipEnd = add(t0, scale(sub(t1, t0), 0.12));
      cylinder(cp, cc, cn, t0, tipEnd, 0.6, 0.6, [0.7, 0.7, 0.72]);
      cylinder(cp, cc, cn, tipEnd, t1, 6, 14, DARK);
    }
    var c7 = frameVec(F.table, 9, f, 0);
    if (isFinite(c7[0])) {
      var c8 = frameVec(F.table, 9, f, 1), tn = frameVec(F.table, 9, f, 2);
      var size = Math.max(120, 0.7 * sceneRadius(false));
      cylinder(cp, cc, cn, c7, c8, 0.04 * R, 0.04 * R, STEEL);
      cylinder(cp, cc, cn, sub(c7, [0, 0.08 * R, 0]), add(c7, [0, 0.08 * R, 0]), 0.06 * R, 0.06 * R, STEEL);
      cylinder(cp, cc, cn, sub(c8, scale(tn, 20)), c8, size, size, STEEL);
      cylinder(cp, cc, cn, sub(c7, [0, 0, 0.05 * R]), [c7[0], c7[1], Math.min(c7[2], -0.02 * R) - 0.3 * R], 0.07 * R, 0.07 * R, DARK);
    }
    cellMesh = cp.length ? mesh([new Float32Array(cp), new Float32Array(cc), new Float32Array(cn)]) : null;
    buildBodies(f);
    cellMeshFrame = f;
  }

  // ---- camera ----
  var partBox = (function () {
    var lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    for (var i = 0; i < N; i++) for (var k = 0; k < 3; k++) { var v = pos[3 * i + k]; if (v < lo[k]) lo[k] = v; if (v > hi[k]) hi[k] = v; }
    if (fitVerts) for (i = 0; i < fitVerts.length; i++) { k = i % 3; v = fitVerts[i]; if (v < lo[k]) lo[k] = v; if (v > hi[k]) hi[k] = v; }
    return { lo: lo, hi: hi };
  })();
  var cellBox = null;
  if (F) {
    var clo = [Infinity, Infinity, Infinity], chi = [-Infinity, -Infinity, -Infinity];
    var grow = function (p) { if (!isFinite(p[0])) return; for (var k = 0; k < 3; k++) { clo[k] = Math.min(clo[k], p[k]); chi[k] = Math.max(chi[k], p[k]); } };
    for (var f = 0; f < F.n; f++) {
      for (var k = 0; k < 8; k++) grow(frameVec(F.chain, 24, f, k));
      grow(frameVec(F.torch, 6, f, 0)); grow(frameVec(F.torch, 6, f, 1)); grow(frameVec(F.table, 9, f, 0));
      var m = partModel(f);
      if (m) { grow(apply(m, partBox.lo)); grow(apply(m, partBox.hi)); }
    }
    grow([0, 0, 0]);
    cellBox = { lo: clo, hi: chi };
  }
  function box() { return state.cell && cellBox ? cellBox : partBox; }
  function sceneRadius(cellView) {
    var b = cellView && cellBox ? cellBox : partBox;
    return Math.max(1, 0.5 * norm(sub(b.hi, b.lo)));
  }
  var cam = { target: [0, 0, 0], dist: 100, yaw: -0.9, pitch: 0.45 };
  var FOV = 40 * Math.PI / 180;
  function resetView() {
    var b = box();
    cam.target = scale(add(b.lo, b.hi), 0.5);
    cam.dist = sceneRadius(state.cell) / Math.sin(FOV / 2) * 1.05;
    cam.yaw = -0.9; cam.pitch = 0.45;
    requestRender();
  }
  function eye() {
    var cp = Math.cos(cam.pitch);
    return add(cam.target, scale([cp * Math.cos(cam.yaw), cp * Math.sin(cam.yaw), Math.sin(cam.pitch)], cam.dist));
  }
  var view = IDENTITY, proj = IDENTITY;
  function cssSize() { return [canvas.clientWidth || 1, canvas.clientHeight || 1]; }
  function updateMatrices() {
    var s = cssSize(), r = sceneRadius(state.cell);
    view = lookAt(eye(), cam.target, [0, 0, 1]);
    proj = perspective(FOV, s[0] / s[1], Math.max(cam.dist - 3 * r, cam.dist * 0.01, 1e-3), cam.dist + 3 * r);
  }
  function partMatrix() {
    if (state.cell && F) return partModel(state.frame) || IDENTITY;
    return IDENTITY;
  }

  // ---- drawing ----
  var BG = [0.12, 0.135, 0.16];
  var needRender = false;
  function requestRender() {
    if (needRender) return;
    needRender = true;
    requestAnimationFrame(function (now) { needRender = false; tick(now); render(); });
  }
  function resize() {
    var dpr = window.devicePixelRatio || 1, s = cssSize();
    var w = Math.max(1, Math.round(s[0] * dpr)), h = Math.max(1, Math.round(s[1] * dpr));
    if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; overlay.width = w; overlay.height = h; }
  }
  function render() {
    resize();
    updateMatrices();
    gl.viewport(0, 0, canvas.width, canvas.height);
    gl.disable(gl.SCISSOR_TEST);
    gl.clearColor(BG[0], BG[1], BG[2], 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    gl.enable(gl.DEPTH_TEST);
    gl.disable(gl.BLEND);
    var vp = mul(proj, view), model = partMatrix(), mvp = mul(vp, model);
    var light = unit(sub(eye(), cam.target));
    var only = state.only;
    if (fitMesh && state.mesh && (!only || only === 'mesh')) {
      if (state.unlit) draw(flat, fitMesh, gl.TRIANGLES, 0, fitMesh.count, mvp, {});
      else draw(lit, fitMesh, gl.TRIANGLES, 0, fitMesh.count, mvp, { model: model, light: light });
    }
    if (!only || only === 'path') {
      draw(flat, pathMesh, gl.LINES, segStart[state.lo], segStart[state.hi + 1] - segStart[state.lo], mvp, {});
      if (state.axes && !FIT) draw(flat, axesMesh, gl.LINES, axStart[state.lo], axStart[state.hi + 1] - axStart[state.lo], mvp, {});
      if (state.marks && marksMesh) draw(flat, marksMesh, gl.POINTS, 0, marksMesh.count, mvp, { size: 9 });
      if (state.marks && cornersMesh) draw(flat, cornersMesh, gl.POINTS, 0, cornersMesh.count, mvp, { size: 7 });
      if (hoverMesh) draw(flat, hoverMesh, gl.POINTS, 0, 1, mvp, { size: 13 });
    }
    if (F && state.cell && (!only || only === 'cell')) {
      if (cellMeshFrame !== state.frame) buildCell(state.frame);
      draw(lit, cellMesh, gl.TRIANGLES, 0, cellMesh ? cellMesh.count : 0, vp, { light: light });
      if (state.bodies) {
        // the highlighted pair on top of everything, the other bodies translucent
        if (hiMesh) {
          gl.disable(gl.DEPTH_TEST);
          draw(lit, hiMesh, gl.TRIANGLES, 0, hiMesh.count, vp, { light: light });
          gl.enable(gl.DEPTH_TEST);
        }
        gl.enable(gl.BLEND);
        gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA);
        gl.depthMask(false);
        if (bodyMesh) draw(lit, bodyMesh, gl.TRIANGLES, 0, bodyMesh.count, vp, { light: light, alpha: 0.16 });
        // the part's wall so far when it is one of the pair, on top too
        if (partHighlighted) {
          var upto = Math.min(L - 1, F.layer[state.frame]);
          gl.disable(gl.DEPTH_TEST);
          draw(lit, wallMesh, gl.TRIANGLES, 0, wStart[upto + 1], mvp, { model: model, light: light, alpha: 0.8, tint: [HIGHLIGHT[0], HIGHLIGHT[1], HIGHLIGHT[2], 1] });
          gl.enable(gl.DEPTH_TEST);
        }
        gl.depthMask(true);
        gl.disable(gl.BLEND);
      }
    }
    if (!only) {
      // translucent surfaces last, without depth writes
      gl.enable(gl.BLEND);
      gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA);
      gl.depthMask(false);
      if (state.substrate && subMesh) draw(lit, subMesh, gl.TRIANGLES, 0, subMesh.count, mvp, { model: model, light: light, alpha: 0.35 });
      if (FIT && state.tube) {
        // pushed back a little: it shows where it stands out of the mesh,
        // not in stripes where the two coincide
        gl.enable(gl.POLYGON_OFFSET_FILL);
        gl.polygonOffset(2, 2);
        draw(lit, tubeMesh, gl.TRIANGLES, 0, tubeMesh.count, mvp, { model: model, light: light, alpha: 0.3 });
        gl.disable(gl.POLYGON_OFFSET_FILL);
      }
      if (state.wall && !FIT) draw(lit, wallMesh, gl.TRIANGLES, wStart[state.lo], wStart[state.hi + 1] - wStart[state.lo], mvp, { model: model, light: light, alpha: 0.45 });
      gl.depthMask(true);
      gl.disable(gl.BLEND);
      drawTriad();
    }
    drawOverlay();
  }
  var triadMesh = mesh([new Float32Array([0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 1]),
    new Float32Array([1, 0.3, 0.3, 1, 0.3, 0.3, 0.3, 0.9, 0.3, 0.3, 0.9, 0.3, 0.35, 0.55, 1, 0.35, 0.55, 1])]);
  var TRIAD = 90;
  function triadRotation() { var r = new Float32Array(view); r[12] = r[13] = r[14] = 0; return r; }
  function drawTriad() {
    var dpr = window.devicePixelRatio || 1, s = Math.round(TRIAD * dpr);
    gl.enable(gl.SCISSOR_TEST);
    gl.scissor(0, 0, s, s);
    gl.viewport(0, 0, s, s);
    gl.clear(gl.DEPTH_BUFFER_BIT);
    draw(flat, triadMesh, gl.LINES, 0, 6, mul(ortho(1.4), triadRotation()), {});
    gl.disable(gl.SCISSOR_TEST);
    gl.viewport(0, 0, canvas.width, canvas.height);
  }
  function drawOverlay() {
    var g = overlay.getContext('2d'), dpr = window.devicePixelRatio || 1, s = cssSize();
    g.setTransform(dpr, 0, 0, dpr, 0, 0);
    g.clearRect(0, 0, s[0], s[1]);
    g.font = '12px sans-serif';
    g.fillStyle = '#e6e8ec';
    // triad labels
    var r = triadRotation();
    [['X', [1, 0, 0]], ['Y', [0, 1, 0]], ['Z', [0, 0, 1]]].forEach(function (a) {
      var q = apply(r, a[1]);
      g.fillText(a[0], TRIAD / 2 + q[0] / 1.4 * TRIAD / 2 * 1.15 - 4, s[1] - (TRIAD / 2 + q[1] / 1.4 * TRIAD / 2 * 1.15) + 4);
    });
    g.fillText(state.cell && F ? 'robot base frame' : 'part frame', 8, s[1] - TRIAD - 6);
    // scale bar: mm per CSS pixel at the orbit centre
    var perPx = 2 * cam.dist * Math.tan(FOV / 2) / s[1], want = 120 * perPx;
    var p10 = Math.pow(10, Math.floor(Math.log(want) / Math.LN10)), nice = p10;
    [1, 2, 5, 10].forEach(function (k) { if (k * p10 <= want) nice = k * p10; });
    var px = nice / perPx, x0 = s[0] - px - 20, y0 = s[1] - 20;
    g.fillRect(x0, y0, px, 3); g.fillRect(x0, y0 - 5, 2, 8); g.fillRect(x0 + px - 2, y0 - 5, 2, 8);
    g.textAlign = 'center';
    g.fillText((nice >= 1 ? String(nice) : nice.toPrecision(1)) + ' mm', x0 + px / 2, y0 - 7);
    g.textAlign = 'left';
    if (F && state.cell && !isFinite(F.chain[24 * state.frame])) {
      g.fillStyle = '#ff6b6b';
      g.fillText('no joint solution at this point', 8, 18);
    }
    var cl = F && state.cell ? closestAt(state.frame) : null;
    if (cl) {
      g.font = 'bold 13px sans-serif';
      g.fillStyle = cl.collision ? '#ff4d4d' : '#ffb199';
      g.fillText(cl.text, 8, 36);
    }
  }

  // ---- picking: nearest drawn point on screen ----
  function project(m, p, s) {
    var c = apply(m, p);
    if (c[3] <= 0) return null;
    return [(c[0] / c[3] * 0.5 + 0.5) * s[0], (0.5 - c[1] / c[3] * 0.5) * s[1], c[2] / c[3]];
  }
  // on a fit page: the nearest mesh vertex on screen
  function pickVertex(x, y) {
    updateMatrices();
    var m = mul(proj, view), s = cssSize(), best = -1, bestD = 64, nv = fitVerts.length / 3;
    for (var i = 0; i < nv; i++) {
      var q = project(m, [fitVerts[3 * i], fitVerts[3 * i + 1], fitVerts[3 * i + 2]], s);
      if (!q || q[2] < -1 || q[2] > 1) continue;
      var d = (q[0] - x) * (q[0] - x) + (q[1] - y) * (q[1] - y);
      if (d < bestD) { bestD = d; best = i; }
    }
    var tip = $('tip');
    if (best < 0) { tip.hidden = true; hoverMesh = null; requestRender(); return null; }
    var p = [fitVerts[3 * best], fitVerts[3 * best + 1], fitVerts[3 * best + 2]];
    var text = 'mesh vertex ' + best + ' of ' + nv +
      '\nx ' + fmt(p[0], 2) + ', y ' + fmt(p[1], 2) + ', z ' + fmt(p[2], 2) + ' mm (part frame)';
    fields.forEach(function (f) { if (f.mesh) text += '\n' + f.name + ': ' + fmt(f.data[best], 4) + ' ' + f.unit; });
    tip.textContent = text;
    tip.hidden = false;
    tip.style.left = Math.min(x + 14, cssSize()[0] - tip.offsetWidth - 4) + 'px';
    tip.style.top = Math.max(4, y - tip.offsetHeight - 8) + 'px';
    hoverMesh = mesh([new Float32Array(p), new Float32Array([1, 1, 1])]);
    requestRender();
    return { vertex: best, text: text };
  }
  function pickAt(x, y) {
    if (FIT) return pickVertex(x, y);
    updateMatrices();
    var m = mul(mul(proj, view), partMatrix()), s = cssSize(), best = -1, bestD = 64;
    for (var i = layerStart[state.lo]; i < layerStart[state.hi + 1]; i++) {
      var q = project(m, [pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]], s);
      if (!q || q[2] < -1 || q[2] > 1) continue;
      var d = (q[0] - x) * (q[0] - x) + (q[1] - y) * (q[1] - y);
      if (d < bestD) { bestD = d; best = i; }
    }
    var tip = $('tip');
    if (best < 0) { tip.hidden = true; hoverMesh = null; requestRender(); return null; }
    var l = layerOf[best], k = best - layerStart[l];
    var idx = Math.min(k * D.stride, D.layer_points[l] - 1);
    var p = vtx(best);
    var text = 'layer ' + l + ' (slice ' + D.layer_slice[l] + '), point ' + idx + ' of ' + D.layer_points[l] +
      '\nx ' + fmt(p[0], 2) + ', y ' + fmt(p[1], 2) + ', z ' + fmt(p[2], 2) + ' mm (part frame)';
    fields.forEach(function (f) { if (f.key !== 'layer') text += '\n' + f.name + ': ' + fmt(f.data[best]) + ' ' + f.unit; });
    if (markText[l + ':' + idx]) text += '\n' + markText[l + ':' + idx];
    tip.textContent = text;
    tip.hidden = false;
    tip.style.left = Math.min(x + 14, cssSize()[0] - tip.offsetWidth - 4) + 'px';
    tip.style.top = Math.max(4, y - tip.offsetHeight - 8) + 'px';
    hoverMesh = mesh([new Float32Array(p), new Float32Array([1, 1, 1])]);
    requestRender();
    return { vertex: best, layer: l, point: idx, text: text };
  }

  // ---- mouse ----
  var drag = null, hoverPending = null;
  canvas.addEventListener('contextmenu', function (e) { e.preventDefault(); });
  canvas.addEventListener('mousedown', function (e) {
    drag = { x: e.clientX, y: e.clientY, pan: e.button === 2 || e.shiftKey || e.button === 1 };
    $('tip').hidden = true;
    e.preventDefault();
  });
  window.addEventListener('mouseup', function () { drag = null; });
  window.addEventListener('mousemove', function (e) {
    if (drag) {
      var dx = e.clientX - drag.x, dy = e.clientY - drag.y;
      drag.x = e.clientX; drag.y = e.clientY;
      if (drag.pan) {
        var perPx = 2 * cam.dist * Math.tan(FOV / 2) / cssSize()[1];
        var right = [view[0], view[4], view[8]], up = [view[1], view[5], view[9]];
        cam.target = add(cam.target, add(scale(right, -dx * perPx), scale(up, dy * perPx)));
      } else {
        cam.yaw -= dx * 0.008;
        cam.pitch = Math.max(-1.55, Math.min(1.55, cam.pitch + dy * 0.008));
      }
      requestRender();
    } else if (e.target === canvas) {
      var r = canvas.getBoundingClientRect();
      if (!hoverPending) requestAnimationFrame(function () { var h = hoverPending; hoverPending = null; if (h) pickAt(h[0], h[1]); });
      hoverPending = [e.clientX - r.left, e.clientY - r.top];
    }
  });
  canvas.addEventListener('wheel', function (e) {
    e.preventDefault();
    cam.dist *= Math.exp(Math.max(-1, Math.min(1, e.deltaY * 0.0015)));
    requestRender();
  }, { passive: false });
  window.addEventListener('resize', requestRender);

  // ---- controls ----
  fieldSel.addEventListener('change', function () { state.field = +fieldSel.value; recolour(); requestRender(); });
  [['show-axes', 'axes'], ['show-wall', 'wall'], ['show-substrate', 'substrate'], ['show-marks', 'marks'], ['show-cell', 'cell'], ['show-bodies', 'bodies'],
    ['show-mesh', 'mesh'], ['show-tube', 'tube']].forEach(function (c) {
    var el = $(c[0]);
    el.addEventListener('change', function () {
      state[c[1]] = el.checked;
      if (c[1] === 'cell') resetView();
      requestRender();
    });
  });
  $('reset').addEventListener('click', resetView);
  function setRange(lo, hi) {
    state.lo = Math.max(0, Math.min(lo, L - 1)); state.hi = Math.max(state.lo, Math.min(hi, L - 1));
    loSlider.value = String(state.lo); hiSlider.value = String(state.hi);
    $('layer-label').textContent = state.lo + ' – ' + state.hi + ' of ' + (L - 1);
    rebuildMarks();
    requestRender();
  }
  loSlider.addEventListener('input', function () { var lo = +loSlider.value; setRange(lo, Math.max(lo, state.hi)); });
  hiSlider.addEventListener('input', function () { var hi = +hiSlider.value; setRange(Math.min(hi, state.lo), hi); });

  // ---- animation ----
  var scrub = $('scrub'), lastNow = null;
  function setFrame(f) {
    if (!F) return;
    state.frame = Math.max(0, Math.min(F.n - 1, f));
    state.clock = F.time[state.frame];
    scrub.value = String(state.frame);
    updateJoints();
    requestRender();
  }
  function frameAtTime(t) {
    var lo = 0, hi = F.n - 1;
    while (lo < hi) { var mid = (lo + hi + 1) >> 1; if (F.time[mid] <= t) lo = mid; else hi = mid - 1; }
    return lo;
  }
  function advance(dt) {
    state.clock += dt * state.speed;
    var end = F.time[F.n - 1];
    if (state.clock >= end) { state.clock = end; state.playing = false; $('play').textContent = 'Play'; }
    var f = frameAtTime(state.clock);
    if (f !== state.frame) { state.frame = f; scrub.value = String(f); updateJoints(); }
  }
  function tick(now) {
    if (!F || !state.playing) { lastNow = null; return; }
    if (lastNow !== null) advance(Math.min(0.25, (now - lastNow) / 1000));
    lastNow = now;
    if (state.playing) requestRender();
  }
  function updateJoints() {
    var f = state.frame, names = ['J1', 'J2', 'J3', 'J4', 'J5', 'J6', 'E1', 'E2'];
    var t = $('joints');
    t.textContent = '';
    var head = document.createElement('tr');
    ['', 'deg', 'limits', 'margin'].forEach(function (h) { var th = document.createElement('th'); th.textContent = h; head.appendChild(th); });
    t.appendChild(head);
    function row(name, v, lim, margin) {
      var tr = document.createElement('tr');
      [name, fmt(v, 2), lim, fmt(margin, 1)].forEach(function (c) { var td = document.createElement('td'); td.textContent = c; tr.appendChild(td); });
      if (margin < 0) tr.className = 'out'; else if (margin < 10) tr.className = 'near';
      t.appendChild(tr);
    }
    for (var k = 0; k < P.limits_deg.length; k++) {
      var v = F.joints[8 * f + k], lim = P.limits_deg[k];
      var lo = lim[0] === null ? -Infinity : lim[0], hi = lim[1] === null ? Infinity : lim[1];
      var margin = Math.min(v - lo, hi - v);
      row(names[k], v, (isFinite(lo) ? lo.toFixed(0) : '−∞') + ' … ' + (isFinite(hi) ? hi.toFixed(0) : '∞'), isFinite(v) ? margin : NaN);
    }
    if (P.max_hose_deg !== null) {
      var hose = Math.abs(F.joints[8 * f + 3] + F.joints[8 * f + 5]);
      row('|J4+J6|', hose, '≤ ' + P.max_hose_deg.toFixed(0), P.max_hose_deg - hose);
    }
    row('R_Z', F.rz[f], '', NaN);
    $('frame-label').textContent = 'frame ' + (f + 1) + ' of ' + F.n + ': layer ' + F.layer[f] + ', point ' + F.point[f] +
      ', t = ' + fmt(F.time[f], 1) + ' s of ' + fmt(P.duration_s, 1) + ' s under the arc' + cycleText(F.layer[f]);
    var cl = closestAt(f), ce = $('closest');
    ce.textContent = cl ? cl.text : (P.closest.length ? 'closest: \u2014' : 'closest: not checked');
    ce.className = cl && cl.collision ? 'collision' : '';
    document.body.setAttribute('data-closest', ce.textContent);
  }
  // the program's cycle time, and the shown layer's share of it
  function cycleText(layer) {
    if (P.cycle_time_s === null || P.cycle_time_s === undefined) return '';
    var k = P.cycle_layers.indexOf(layer);
    return '; cycle time ' + fmt(P.cycle_time_s, 1) + ' s' +
      (k >= 0 ? ' (layer ' + layer + ': ' + fmt(P.cycle_layer_s[k], 1) + ' s)' : '');
  }
  function focusMark(m) {
    if (F) {
      var best = 0;
      for (var f = 0; f < F.n; f++) if (F.layer[f] < m.layer || (F.layer[f] === m.layer && F.point[f] <= m.point)) best = f;
      setFrame(best);
    }
    setRange(Math.min(state.lo, m.layer), Math.max(state.hi, m.layer));
    hoverMesh = mesh([new Float32Array(m.at), new Float32Array([1, 1, 1])]);
    requestRender();
  }
  if (F) {
    $('plan-controls').hidden = false;
    scrub.max = String(F.n - 1);
    scrub.addEventListener('input', function () { setFrame(+scrub.value); });
    $('speed').addEventListener('change', function () { state.speed = +$('speed').value; });
    $('play').addEventListener('click', function () {
      if (!state.playing && state.frame >= F.n - 1) setFrame(0);
      state.playing = !state.playing;
      $('play').textContent = state.playing ? 'Pause' : 'Play';
      lastNow = null;
      requestRender();
    });
    updateJoints();
  }

  // ---- fit page: radius error (and wall thickness) per station ----
  function drawFitPlot() {
    var c = $('fit-plot'), g = c.getContext('2d'), st = FIT.report.stations;
    var W = c.width, H = c.height, x0 = 50, x1 = W - 8, y0 = 8, y1 = H - 22;
    g.clearRect(0, 0, W, H);
    var ts = [], es = [], ws = [];
    st.forEach(function (s) {
      ts.push(s.t_mm);
      es.push(s.radius_error_mm === null ? NaN : s.radius_error_mm);
      ws.push(s.wall_thickness_mm === null || s.law_thickness_mm === null ? NaN : s.law_thickness_mm - s.wall_thickness_mm);
    });
    var tlo = Math.min.apply(null, ts), thi = Math.max.apply(null, ts), m = 1e-6;
    es.concat(ws).forEach(function (v) { if (isFinite(v)) m = Math.max(m, Math.abs(v)); });
    var X = function (t) { return x0 + (x1 - x0) * (t - tlo) / Math.max(thi - tlo, 1e-9); };
    var Y = function (v) { return y0 + (y1 - y0) * (0.5 - 0.5 * v / m); };
    g.strokeStyle = '#bbb'; g.beginPath(); g.moveTo(x0, Y(0)); g.lineTo(x1, Y(0)); g.stroke();
    [[es, '#c03030'], [ws, '#3060c0']].forEach(function (sv) {
      g.strokeStyle = sv[1]; g.beginPath();
      var pen = false;
      sv[0].forEach(function (v, k) {
        if (!isFinite(v)) { pen = false; return; }
        if (pen) g.lineTo(X(ts[k]), Y(v)); else g.moveTo(X(ts[k]), Y(v));
        pen = true;
      });
      g.stroke();
    });
    g.fillStyle = '#222'; g.font = '10px sans-serif'; g.textAlign = 'right';
    g.fillText('+' + fmt(m, 4), x0 - 2, y0 + 8); g.fillText('0', x0 - 2, Y(0) + 3); g.fillText('−' + fmt(m, 4), x0 - 2, y1);
    g.textAlign = 'left';
    g.fillText('t = ' + fmt(tlo, 1) + ' … ' + fmt(thi, 1) + ' mm along the guide', x0, H - 4);
    $('fit-plot-label').textContent = 'radius law − section radius per station (red, mm)' +
      (FIT.report.wall ? '; wall law − section wall (blue, mm)' : '') + '; largest |error| ' + fmt(m, 4) + ' mm';
  }
  if (FIT) drawFitPlot();

  recolour();
  setRange(0, L - 1);
  resetView();
  render();

  // ---- self-test (opened with #selftest): exercises every control once and
  // writes what it saw, for the browser test ----
  // pixels in the highlight colour: red well above green and blue
  function countHighlight() {
    var w = canvas.width, h = canvas.height, px = new Uint8Array(4 * w * h), n = 0;
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
    for (var i = 0; i < px.length; i += 4) if (px[i] > 120 && px[i] > 2.5 * px[i + 1] && px[i] > 2.5 * px[i + 2]) n++;
    return n;
  }
  function countDrawn() {
    var w = canvas.width, h = canvas.height, px = new Uint8Array(4 * w * h), colours = {}, n = 0;
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
    var bg = BG.map(function (c) { return Math.round(255 * c); });
    for (var i = 0; i < px.length; i += 4) {
      if (Math.abs(px[i] - bg[0]) + Math.abs(px[i + 1] - bg[1]) + Math.abs(px[i + 2] - bg[2]) > 24) {
        n++;
        colours[(px[i] >> 5) + ',' + (px[i + 1] >> 5) + ',' + (px[i + 2] >> 5)] = 1;
      }
    }
    return { pixels: n, colours: Object.keys(colours).length, of: w * h };
  }
  if (/selftest/.test(location.hash)) {
    setTimeout(function () {
      var out = { webgl: true, fields: [], errors_before: errorCount };
      var cellWas = state.cell;
      state.cell = false;
      resetView();
      render();
      out.first = countDrawn();
      fields.forEach(function (f, k) { state.field = k; recolour(); render(); out.fields.push([f.key, countDrawn().colours]); });
      if (FIT) {
        // the mesh alone, unshaded: its colours are the distance field's
        // (and one colour under a field of the guide)
        state.only = 'mesh'; state.unlit = true;
        state.field = 0; recolour(); render();
        out.mesh_only = countDrawn();
        out.mesh_field = fields[0].key;
        state.field = 1; recolour(); render();
        out.mesh_plain = countDrawn();
        state.only = null; state.unlit = false;
      }
      state.field = 0; recolour();
      state.axes = state.wall = state.substrate = state.marks = true;
      render();
      out.all_layers = countDrawn();
      setRange(Math.floor(L / 3), Math.floor(2 * L / 3));
      render();
      out.some_layers = countDrawn();
      var mid = layerStart[Math.floor(L / 2)], s = cssSize();
      updateMatrices();
      var at = vtx(mid);
      if (FIT) { mid = Math.floor(fitVerts.length / 6); at = [fitVerts[3 * mid], fitVerts[3 * mid + 1], fitVerts[3 * mid + 2]]; }
      var q = project(mul(mul(proj, view), partMatrix()), at, s);
      var pick = q ? pickAt(q[0], q[1]) : null;
      out.pick = pick ? { vertex: pick.vertex, wanted: mid, layer: pick.layer, text: pick.text } : null;
      setRange(0, L - 1);
      // the corners and splits marked: drawn, and named on hover
      out.corners = { marked: cornersMesh ? cornersMesh.count : 0, splits: 0, split_pick: null };
      var split = corners.filter(function (m) { return m.split; });
      out.corners.splits = split.length;
      if (split.length && !FIT) {
        resetView(); updateMatrices();
        var sq = project(mul(mul(proj, view), partMatrix()), split[0].at, cssSize());
        var sp = sq ? pickAt(sq[0], sq[1]) : null;
        out.corners.split_pick = sp ? sp.text : null;
      }
      if (F) {
        state.cell = true;
        resetView();
        state.only = 'cell';
        setFrame(Math.floor(F.n / 2));
        render();
        out.robot_only = countDrawn();
        state.only = null;
        render();
        out.cell_view = countDrawn();
        setFrame(0);
        state.playing = true; state.speed = 1000;
        for (var k = 0; k < 5; k++) advance(0.05);
        out.played_to_frame = state.frame;
        out.joint_rows = $('joints').rows.length;
        state.playing = false;
        // the closest pair: the first frame whose layer has one, drawn
        // alone (the cell only), with and without the highlight
        out.bodies = BODIES.map(function (b) { return b.name; });
        var hf = -1;
        for (var f2 = 0; f2 < F.n && hf < 0; f2++) if (closestAt(f2)) hf = f2;
        if (hf >= 0) {
          state.only = 'cell';
          setFrame(hf);
          cellMeshFrame = -1;
          render();
          var on = countHighlight(), names = highlighted.slice();
          state.highlight = false; cellMeshFrame = -1;
          render();
          var off = countHighlight();
          state.highlight = true; cellMeshFrame = -1;
          state.only = null;
          var c3 = closestAt(hf);
          out.closest = { frame: hf, layer: P.closest.length ? P.closest[F.layer[hf]] : null, pair: c3.names, collision: c3.collision,
            text: c3.text, hud: $('closest').textContent, highlighted: names, highlight_pixels: on, highlight_pixels_off: off };
        }
      }
      state.cell = cellWas;
      resetView();
      render();
      out.last = countDrawn();
      out.errors = errorCount;
      out.resources = loadedResources();
      $('selftest').textContent = JSON.stringify(out);
      $('selftest').hidden = false;
      document.body.setAttribute('data-selftest', 'done');
    }, 0);
  }
})();
