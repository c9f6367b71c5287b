// The website's precomputed sliders (copied by tools/build_site.py to assets/site/).
//
// The page holds, in <script id="site-states">, what geomlib.teaching.display.site_states
// recorded when the site was built: per cell, its sliders, each with its values
// and, per value, the new contents of the widget traits its callback changed
// (pythreejs buffer arrays, read-out text). This script finds those widget models
// in the page's widget manager, and when a reader moves a slider it snaps the
// slider to the nearest computed value (one value further in the direction moved,
// so a key press always gets somewhere) and sets the recorded traits. A slider's
// default value restores what the page was saved with. Sliders of one cell move
// one at a time: moving one puts the others back to their defaults.
(function () {
  "use strict";
  var element = document.getElementById("site-states");
  if (!element) return;
  var groups = JSON.parse(element.textContent);
  window.siteStates = groups;  // for the browser test

  // the widget manager is made by the html-manager's embed script, which the page adds
  // at DOMContentLoaded and which renders the widgets at the window's load; its
  // set_state resolves to the page's models once they exist
  document.addEventListener("DOMContentLoaded", function () {
    var embed = Array.prototype.find.call(document.scripts, function (s) { return /embed-amd\.js$/.test(s.src); });
    if (embed) embed.addEventListener("load", patch);
  });

  function patch() {
    require(["@jupyter-widgets/html-manager"], function (htmlManager) {
    var proto = htmlManager.HTMLManager.prototype;
    var setState = proto.set_state;
    proto.set_state = function () {
      var manager = this;
      return setState.apply(this, arguments).then(function (models) {
        wire(manager).then(
          function () { document.body.setAttribute("data-site-states", "ready"); },
          function (error) { console.error("site_states: " + error); }
        );
        return models;
      });
    };
    });
  }

  function gunzip(text) {
    // base64 of gzip of little-endian 16-bit numbers -> Uint16Array (the browser's own gunzip)
    var bytes = Uint8Array.from(atob(text), function (c) { return c.charCodeAt(0); });
    var stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream("gzip"));
    return new Response(stream).arrayBuffer().then(function (buffer) { return new Uint16Array(buffer); });
  }

  function decode(base, encoded, state) {
    // base: the page's own ndarray ({data, shape, stride, offset}); the recorded columns replace its own
    var data = new Float32Array(base.data);
    var width = data.length / base.shape[0];
    var q = state.values;
    var columns = encoded.columns, k = columns.length;
    for (var c = 0; c < k; c++) {
      var lo = state.lo[c], scale = (state.hi[c] - lo) / 65535, col = columns[c];
      for (var r = 0, i = col, j = c; r < base.shape[0]; r++, i += width, j += k) data[i] = lo + q[j] * scale;
    }
    return {data: data, shape: base.shape.slice(), stride: base.stride.slice(), offset: 0};
  }

  function wire(manager) {
    var ids = {};
    groups.forEach(function (group) {
      group.sliders.forEach(function (s) {
        ids[s.model_id] = true;
        s.traits.forEach(function (t) { ids[t.model_id] = true; });
      });
    });
    var models = {};
    var loading = Object.keys(ids).map(function (id) {
      return manager.get_model(id).then(function (m) { models[id] = m; });
    });
    groups.forEach(function (group) {
      group.sliders.forEach(function (s) {
        s.traits.forEach(function (t) {
          (t.array ? t.states : []).forEach(function (state) {
            if (state) loading.push(gunzip(state.q).then(function (q) { state.values = q; }));
          });
        });
      });
    });
    return Promise.all(loading).then(function () {
      groups.forEach(function (group) { wireGroup(group, models); });
    });
  }

  function wireGroup(group, models) {
    var busy = false;
    group.sliders.forEach(function (s) {
      s.model = models[s.model_id];
      s.current = s.default;
      s.traits.forEach(function (t) {
        t.model = models[t.model_id];
        t.original = t.model.get(t.trait);
        t.cache = {};
      });
      s.model.set("disabled", false);
      s.model.on("change:value", function (model, value) {
        if (busy) return;
        busy = true;
        try {
          var j = snap(s, value);
          if (s.values[j] !== value) model.set("value", s.values[j]);
          group.sliders.forEach(function (other) {
            if (other !== s && other.current !== other.default) {
              other.model.set("value", other.values[other.default]);
              show(other, other.default);
            }
          });
          show(s, j);
        } finally {
          busy = false;
        }
      });
    });
  }

  function snap(s, value) {
    var f = s.log ? Math.log : function (x) { return x; };
    var best = 0;
    for (var j = 1; j < s.values.length; j++) {
      if (Math.abs(f(s.values[j]) - f(value)) < Math.abs(f(s.values[best]) - f(value))) best = j;
    }
    var here = s.values[s.current];
    if (best === s.current && Math.abs(f(value) - f(here)) > 1e-9 * (1 + Math.abs(f(here)))) {
      best = Math.max(0, Math.min(s.values.length - 1, best + (value > here ? 1 : -1)));
    }
    return best;
  }

  function show(s, j) {
    s.traits.forEach(function (t) {
      var value;
      if (j === s.default) value = t.original;
      else if (t.array) value = t.cache[j] || (t.cache[j] = decode(t.original, t.array, t.states[j]));
      else value = t.states[j];
      t.model.set(t.trait, value);
    });
    s.current = j;
  }
})();
