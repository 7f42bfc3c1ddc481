// The player: draws frame k of the selected clip from DATA (positions, t, energy), and
// advances it on a timer (timers, unlike animation frames, also run under a browser's
// virtual time).
(function () {
  'use strict';
  var D = DATA;
  function $(id) { return document.getElementById(id); }
  var links = D.lines.map(function (_, i) { return $('l' + i); });
  var joints = D.dots.map(function (_, i) { return $('d' + i); });
  var traces = D.traces.map(function (_, i) { return $('tr' + i); });
  var centres = D.centres.map(function (_, i) { return $('c' + i); });
  var play = $('play'), speed = $('speed'), scrub = $('scrub'), choice = $('clip');
  var time = $('time'), frame = $('frame'), energy = $('energy'), drift = $('drift');
  var event = $('event'), marks = $('marks');
  var clip = null, k = 0, clock = 0, playing = true, last = null, paths = [];

  function select(c) {
    clip = D.clips[c];
    $('info').textContent = clip.info;
    scrub.max = String(clip.t.length - 1);
    // The traced paths, sampled `clip.sub` times per frame.
    paths = clip.trail.map(function (xy) {
      var a = new Array(xy.length / 2);
      for (var j = 0; j < a.length; j++) { a[j] = xy[2 * j] + ',' + xy[2 * j + 1]; }
      return a;
    });
    // A tick under the slider at each transition of the contacts (impact, lift-off, stick,
    // slip), its text as a tooltip.
    marks.textContent = '';
    align();
    var span = clip.t[clip.t.length - 1] - clip.t[0];
    (clip.ev || []).forEach(function (e) {
      var tick = document.createElement('span');
      tick.style.left = (span > 0 ? 100 * (e[0] - clip.t[0]) / span : 0) + '%';
      tick.title = 't = ' + e[0] + ' s: ' + e[1];
      marks.appendChild(tick);
    });
    clock = 0;
    show(0);
  }

  // The strip of ticks spans the slider's track.
  function align() {
    var r = scrub.getBoundingClientRect();
    marks.style.marginLeft = '0px';
    var m = marks.getBoundingClientRect();
    marks.style.marginLeft = (r.left - m.left) + 'px';
    marks.style.width = r.width + 'px';
  }
  window.addEventListener('resize', align);

  function show(j) {
    k = j;
    var xy = clip.xy[j];
    D.lines.forEach(function (l, i) {
      var e = links[i];
      e.setAttribute('x1', xy[2 * l[0]]); e.setAttribute('y1', xy[2 * l[0] + 1]);
      e.setAttribute('x2', xy[2 * l[1]]); e.setAttribute('y2', xy[2 * l[1] + 1]);
    });
    D.dots.forEach(function (p, i) {
      joints[i].setAttribute('cx', xy[2 * p]); joints[i].setAttribute('cy', xy[2 * p + 1]);
    });
    D.centres.forEach(function (p, i) {
      centres[i].setAttribute('cx', xy[2 * p]); centres[i].setAttribute('cy', xy[2 * p + 1]);
    });
    traces.forEach(function (e, i) { e.setAttribute('points', paths[i].slice(0, j * clip.sub + 1).join(' ')); });
    // The 3-D view, once loaded, draws the same frame (`animate3d.js`).
    window.eomgenPlayer = { clip: clip, k: j };
    if (window.eomgenShow3d) { window.eomgenShow3d(clip, j); }
    scrub.value = String(j);
    var t = clip.t[j];
    if (clip.period) {
      time.textContent = 't = ' + t.toPrecision(4) + ' s (' + (360 * t / clip.period).toFixed(0) + '° of the cycle)';
    } else {
      time.textContent = 't = ' + t.toFixed(3) + ' s';
    }
    time.setAttribute('data-t', String(t));
    frame.textContent = 'frame ' + (j + 1) + ' / ' + clip.t.length;
    frame.setAttribute('data-frame', String(j));
    if (clip.e) {
      energy.textContent = 'E = ' + clip.e[j].toPrecision(9) + ' J';
      drift.textContent = (clip.ev ? '(E + lost − E₀)' : '(E − E₀)') + ' / max(T + |V|) = ' + clip.de[j].toExponential(2);
    } else {
      energy.textContent = '';
      drift.textContent = '';
    }
    // The latest transition this frame shows the state after, and how many there have been.
    var seen = 0, ev = clip.ev || [];
    while (seen < ev.length && ev[seen][2] <= j) { seen++; }
    event.textContent = seen > 0
      ? 'transition ' + seen + ' / ' + ev.length + ' at t = ' + Number(ev[seen - 1][0]).toFixed(4) + ' s: ' + ev[seen - 1][1]
      : (ev.length > 0 ? ev.length + ' transitions ahead' : '');
  }

  // The last frame at or before the clip's start plus `c` seconds.
  function frameAt(c) {
    var t = clip.t[0] + c, lo = 0, hi = clip.t.length - 1;
    while (lo < hi) {
      var mid = (lo + hi + 1) >> 1;
      if (clip.t[mid] <= t + 1e-12 * Math.abs(t)) { lo = mid; } else { hi = mid - 1; }
    }
    return lo;
  }

  function setPlaying(p) {
    playing = p;
    play.textContent = p ? 'Pause' : 'Play';
    last = null;
  }

  function tick() {
    var now = performance.now();
    if (playing && last !== null && clip.t.length > 1) {
      clock += (now - last) / 1000 * Number(speed.value) * clip.rate;
      var span = clip.t[clip.t.length - 1] - clip.t[0];
      if (clock > span) { clock = clip.period ? clock % span : 0; }
      var j = frameAt(clock);
      if (j !== k) { show(j); }
    }
    last = now;
    setTimeout(tick, 15);
  }

  play.addEventListener('click', function () { setPlaying(!playing); });
  scrub.addEventListener('input', function () {
    setPlaying(false);
    var j = Number(scrub.value);
    clock = clip.t[j] - clip.t[0];
    show(j);
  });
  if (choice) { choice.addEventListener('change', function () { select(Number(choice.value)); }); }
  document.addEventListener('keydown', function (e) {
    var tag = e.target && e.target.tagName;
    if ((e.key === ' ' || e.code === 'Space') && tag !== 'BUTTON' && tag !== 'SELECT') {
      e.preventDefault();
      setPlaying(!playing);
    } else if ((e.key === 'ArrowRight' || e.key === 'ArrowLeft') && tag !== 'INPUT' && tag !== 'SELECT') {
      e.preventDefault();
      setPlaying(false);
      var j = Math.max(0, Math.min(clip.t.length - 1, k + (e.key === 'ArrowRight' ? 1 : -1)));
      clock = clip.t[j] - clip.t[0];
      show(j);
    }
  });
  select(0);
  setPlaying(true);
  document.body.setAttribute('data-state', 'ready');
  setTimeout(tick, 15);
})();
