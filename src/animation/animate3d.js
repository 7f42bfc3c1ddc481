// The 3-D view of a 3-D model's page: the bodies as solids turned with their frames, their
// axes (x red, y green, z blue), the drawn lines and traced paths, over a grid in the ground
// plane, with an orbit camera and iso, top and side views. three.js (vendored, gzip and base64
// inside the page) is loaded without a network; where WebGL is missing the page keeps its
// isometric drawing and says why. The player calls `window.eomgenShow3d(clip, k)` at each
// frame it shows.
(function () {
  'use strict';
  var D = DATA;
  D.clips.forEach(function (c, i) {
    var s = D.space[i] || { xyz: [], trail3: [], pose: [] };
    c.xyz = s.xyz; c.trail3 = s.trail3; c.pose = s.pose;
  });
  function $(id) { return document.getElementById(id); }

  function fallback(why) {
    document.body.setAttribute('data-view', 'svg');
    $('scene').style.display = '';
    $('view3d').hidden = true;
    $('views').hidden = true;
    $('view-note').textContent = '3-D view unavailable (' + why + '); isometric drawing shown';
  }

  // three.js from the page itself: base64 → gzip → an ES module.
  function load() {
    var text = $('three-gz').textContent;
    var raw = atob(text.trim());
    var bytes = new Uint8Array(raw.length);
    for (var i = 0; i < raw.length; i++) { bytes[i] = raw.charCodeAt(i); }
    var stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream('gzip'));
    return new Response(stream).text().then(function (js) {
      return import(URL.createObjectURL(new Blob([js], { type: 'text/javascript' })));
    });
  }

  // The box of every point, centre and trail of every clip: its centre and largest side.
  function bounds() {
    var lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    function add(a, stride, offset) {
      for (var i = offset; i + 2 < a.length + 0; i += stride) {
        for (var k = 0; k < 3; k++) {
          lo[k] = Math.min(lo[k], a[i + k]); hi[k] = Math.max(hi[k], a[i + k]);
        }
      }
    }
    D.clips.forEach(function (c) {
      c.xyz.forEach(function (f) { add(f, 3, 0); });
      c.pose.forEach(function (f) { add(f, 7, 0); });
      c.trail3.forEach(function (p) { add(p, 3, 0); });
    });
    var size = Math.max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
    // The mechanism's own size: the largest over the frames of one frame's box.
    var own = 0;
    D.clips.forEach(function (c) {
      c.xyz.forEach(function (f, k) { own = Math.max(own, frameBox(f, c.pose[k]).size); });
    });
    D.bodies.forEach(function (b) { own = Math.max(own, b.extent); size = Math.max(size, b.extent); });
    if (!(size > 0)) { size = 1; }
    if (!(own > 0)) { own = size; }
    return { lo: lo, hi: hi, size: size, own: own, centre: [0, 1, 2].map(function (k) { return 0.5 * (lo[k] + hi[k]); }) };
  }

  // The box of one frame's points and body centres: its centre and largest side.
  function frameBox(xyz, pose) {
    var lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    function add(a, stride) {
      for (var i = 0; i + 2 < a.length; i += stride) {
        for (var k = 0; k < 3; k++) { lo[k] = Math.min(lo[k], a[i + k]); hi[k] = Math.max(hi[k], a[i + k]); }
      }
    }
    add(xyz, 3);
    add(pose, 7);
    if (!(lo[0] <= hi[0])) { return { centre: [0, 0, 0], size: 0 }; }
    return {
      centre: [0, 1, 2].map(function (k) { return 0.5 * (lo[k] + hi[k]); }),
      size: Math.max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2])
    };
  }

  // A square grid of `cells` × `cells` cells of side `step` centred at `at`, in the plane
  // z = at[2], the lines through x = 0 and y = 0 darker. Each cell's side is its own segment:
  // a software renderer drops a long line that passes behind the camera.
  function grid(T, cells, step, at) {
    var light = [], dark = [], half = cells / 2;
    for (var i = -half; i <= half; i++) {
      for (var j = -half; j < half; j++) {
        var u = at[0] + i * step, v0 = at[1] + j * step, v1 = v0 + step;
        var x = at[0] + j * step, x1 = x + step, y = at[1] + i * step;
        (Math.abs(u) < 1e-9 * step ? dark : light).push(u, v0, at[2], u, v1, at[2]);
        (Math.abs(y) < 1e-9 * step ? dark : light).push(x, y, at[2], x1, y, at[2]);
      }
    }
    var group = new T.Group();
    [[light, 0xe4e4e4], [dark, 0xb8b8b8]].forEach(function (part) {
      var g = new T.BufferGeometry();
      g.setAttribute('position', new T.BufferAttribute(new Float32Array(part[0]), 3));
      group.add(new T.LineSegments(g, new T.LineBasicMaterial({ color: part[1] })));
    });
    return group;
  }

  function start(T) {
    var canvas = $('view3d');
    var renderer;
    try {
      renderer = new T.WebGLRenderer({ canvas: canvas, antialias: true, preserveDrawingBuffer: true });
    } catch (e) {
      fallback('no WebGL: ' + e.message);
      return;
    }
    document.body.setAttribute('data-view', 'webgl');
    $('scene').style.display = 'none';
    canvas.hidden = false;
    $('views').hidden = false;
    renderer.setPixelRatio(window.devicePixelRatio || 1);
    var box = bounds(), size = box.size, c = box.centre.slice();
    // A mechanism that travels far beyond its own size (a bicycle, a rolling coin) is
    // followed: the camera keeps its offset from the frame's centre.
    var follow = $('follow');
    follow.checked = box.size > 3 * box.own;
    var near = follow.checked ? box.own : size;
    var scene = new T.Scene();
    scene.background = new T.Color(0xfcfcfc);
    var camera = new T.PerspectiveCamera(35, 1, Math.min(size, box.own) / 200, size * 200);
    camera.up.set(0, 0, 1);
    var light = new T.DirectionalLight(0xffffff, 2.2);
    light.position.set(-0.5, 1, 2);
    // The light shines along the camera's view: its target moves with the camera.
    camera.add(light);
    camera.add(light.target);
    light.target.position.set(0, 0, -1);
    scene.add(camera);
    scene.add(new T.AmbientLight(0xffffff, 1.1));

    // The grid in the ground plane z = 0 (or under the lowest point), the ground's axes.
    var floor = Math.min(0, box.lo[2]);
    // Its spacing: 1, 2 or 5 × 10ᵏ m near a tenth of the run's box, or of the mechanism when
    // it is followed; at most 200 cells a side.
    var raw = near / 10, power = Math.pow(10, Math.floor(Math.log10(raw))), m = raw / power;
    var step = power * (m < 1.5 ? 1 : m < 3.5 ? 2 : m < 7.5 ? 5 : 10);
    var cells = Math.min(200, Math.max(2, 2 * Math.ceil(1.5 * size / step / 2)));
    var floorGrid = grid(T, cells, step, [0, 0, floor]);
    // Centred under `at`, on the grid's own lines.
    function centreGrid(at) {
      floorGrid.position.set(Math.round(at[0] / step) * step, Math.round(at[1] / step) * step, 0);
    }
    centreGrid(c);
    scene.add(floorGrid);
    $('grid-step').textContent = 'grid ' + Number(step.toPrecision(3)) + ' m';
    var ground = new T.AxesHelper(0.25 * near);
    ground.position.set(0, 0, floor);
    scene.add(ground);

    // The bodies: a group at the centre, turned with the frame, holding the frame's axes
    // and the solid (turned within it by `local`).
    var colours = [0xc8553d, 0x3f8f8f, 0x8f5ea2, 0xd9982f, 0x4f6d7a, 0xb56576];
    var groups = D.bodies.map(function (b, i) {
      var g = new T.Group();
      var s = b.solid, geometry;
      if (s[0] === 'box') {
        geometry = new T.BoxGeometry(s[1], s[2], s[3]);
      } else if (s[0] === 'cylinder') {
        geometry = new T.CylinderGeometry(s[1], s[1], s[2], 48);
      } else {
        geometry = new T.SphereGeometry(s[1] > 0 ? s[1] : 0.02 * near, 32, 16);
      }
      var material = new T.MeshLambertMaterial({
        color: colours[i % colours.length], transparent: true, opacity: 0.82
      });
      var mesh = new T.Mesh(geometry, material);
      mesh.quaternion.set(b.local[0], b.local[1], b.local[2], b.local[3]);
      g.add(mesh);
      var axes = new T.AxesHelper(0.75 * Math.max(b.extent, 0.08 * near));
      g.add(axes);
      scene.add(g);
      return g;
    });

    // The drawn lines, the joints and the traced paths.
    var lineGeometry = new T.BufferGeometry();
    lineGeometry.setAttribute('position', new T.BufferAttribute(new Float32Array(6 * D.lines.length), 3));
    scene.add(new T.LineSegments(lineGeometry, new T.LineBasicMaterial({ color: 0x2b59c3 })));
    var jointGeometry = new T.SphereGeometry(0.012 * near, 12, 8);
    var jointMaterial = new T.MeshLambertMaterial({ color: 0x1b1b1b });
    // The joints, but not the 24 points of a drawn wheel's rim (`P.rim0` … `P.rim23`).
    var dots = D.dots.filter(function (p) { return !/\.rim[0-9]+$/.test(D.names[p]); });
    var joints = dots.map(function () {
      var m = new T.Mesh(jointGeometry, jointMaterial);
      scene.add(m);
      return m;
    });
    // The centres of the particles and planar bodies.
    var particleGeometry = new T.SphereGeometry(0.025 * near, 16, 12);
    var particleMaterial = new T.MeshLambertMaterial({ color: 0x555555 });
    var particles = D.particles.map(function () {
      var m = new T.Mesh(particleGeometry, particleMaterial);
      scene.add(m);
      return m;
    });
    var traces = [];

    function selectTraces(clip) {
      traces.forEach(function (t) { scene.remove(t); t.geometry.dispose(); });
      traces = clip.trail3.map(function (path) {
        var g = new T.BufferGeometry();
        g.setAttribute('position', new T.BufferAttribute(new Float32Array(path), 3));
        var line = new T.Line(g, new T.LineBasicMaterial({ color: 0xe8871e }));
        scene.add(line);
        return line;
      });
    }

    function render() { renderer.render(scene, camera); }

    var shown = null;
    function show(clip, k) {
      if (clip !== shown) { selectTraces(clip); shown = clip; }
      var xyz = clip.xyz[k], pose = clip.pose[k];
      var a = lineGeometry.attributes.position.array;
      D.lines.forEach(function (l, i) {
        for (var e = 0; e < 2; e++) {
          for (var m = 0; m < 3; m++) { a[6 * i + 3 * e + m] = xyz[3 * l[e] + m]; }
        }
      });
      lineGeometry.attributes.position.needsUpdate = true;
      lineGeometry.computeBoundingSphere();
      dots.forEach(function (p, i) { joints[i].position.set(xyz[3 * p], xyz[3 * p + 1], xyz[3 * p + 2]); });
      D.particles.forEach(function (p, i) { particles[i].position.set(xyz[3 * p], xyz[3 * p + 1], xyz[3 * p + 2]); });
      groups.forEach(function (g, i) {
        var o = 7 * i;
        g.position.set(pose[o], pose[o + 1], pose[o + 2]);
        g.quaternion.set(pose[o + 3], pose[o + 4], pose[o + 5], pose[o + 6]);
      });
      traces.forEach(function (t) { t.geometry.setDrawRange(0, k * clip.sub + 1); });
      if (follow.checked) { aim(frameBox(xyz, pose).centre); }
      resize();
      render();
    }

    // Moves the orbit's centre to `to`, the camera with it.
    function aim(to) {
      var t = controls.target;
      camera.position.set(camera.position.x + to[0] - t.x, camera.position.y + to[1] - t.y, camera.position.z + to[2] - t.z);
      t.set(to[0], to[1], to[2]);
      c = to;
      centreGrid(to);
      controls.update();
    }

    var controls = new T.OrbitControls(camera, canvas);
    controls.target.set(c[0], c[1], c[2]);
    controls.addEventListener('change', render);
    follow.addEventListener('change', function () {
      if (!follow.checked) { return; }
      var now = window.eomgenPlayer;
      if (now) { show(now.clip, now.k); }
    });

    // iso: the isometric drawing's direction (x to the right and down, y to the left);
    // top: down the z axis, y up; side: along y, x to the right, z up.
    // (The top view is a hair off the vertical: the orbit keeps z up.)
    var views = { iso: [-1, -1, 1], top: [0, -1e-3, 1], side: [0, -1, 0] };
    function view(name) {
      var d = views[name], n = Math.hypot(d[0], d[1], d[2]), r = 2.6 * near;
      camera.position.set(c[0] + r * d[0] / n, c[1] + r * d[1] / n, c[2] + r * d[2] / n);
      camera.lookAt(c[0], c[1], c[2]);
      controls.update();
      render();
      document.body.setAttribute('data-camera', name);
    }
    Array.prototype.forEach.call(document.querySelectorAll('#views button'), function (b) {
      b.addEventListener('click', function () { view(b.getAttribute('data-view')); });
    });

    // The canvas's size in CSS pixels, followed at each frame too: it changes when the lines
    // above it do (another clip's info).
    var shape = [0, 0];
    function resize() {
      var w = canvas.clientWidth, h = canvas.clientHeight;
      if (w > 0 && h > 0 && (w !== shape[0] || h !== shape[1])) {
        shape = [w, h];
        renderer.setSize(w, h, false);
        camera.aspect = w / h;
        camera.updateProjectionMatrix();
        render();
      }
    }
    window.addEventListener('resize', resize);

    window.eomgenShow3d = show;
    resize();
    // The first view: the page address's `#top`, `#side` or `#iso` (the default).
    var first = window.location.hash.slice(1);
    view(Object.prototype.hasOwnProperty.call(views, first) ? first : 'iso');
    var now = window.eomgenPlayer;
    if (now) { show(now.clip, now.k); }
  }

  if (typeof DecompressionStream === 'undefined') {
    fallback('this browser cannot decompress the embedded three.js');
    return;
  }
  // three.js reports a missing WebGL 2 with console.error; asked first, it is a note.
  if (!document.createElement('canvas').getContext('webgl2')) {
    fallback('WebGL 2 is not available');
    return;
  }
  load().then(start).catch(function (e) { fallback(String(e && e.message || e)); });
})();
