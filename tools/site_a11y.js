// The website's accessibility layer (copied by tools/build_site.py to assets/site/, loaded on
// every notebook page).
//
// The widgets are drawn by the Jupyter widgets HTML manager when the page loads, with markup
// that names nothing; this script completes that markup as the widgets appear and change:
// - every slider handle (role slider) is named by its description, says the value its
//   read-out shows (aria-valuetext: a log-scale slider's aria-valuenow is the exponent), and a
//   disabled one leaves the Tab order and says it is disabled; its read-out box is named and,
//   when disabled, not editable; other controls are named by their label;
// - every 3D view (the box holding the canvas, class geomlib-canvas: pythreejs moves its
//   canvases between views, the box stays) takes keyboard focus, is labelled "3D view" and
//   described by the view's text alternative (the caption under it, class geomlib-alt, which
//   the slider states update) and the key hint after it; with focus, the arrow keys turn it,
//   Shift + arrows pan, + and - zoom and 0 resets the camera (the keys drive the same
//   orbit controls as the mouse);
// - a change a reader makes with a slider is announced in the page's polite live region
//   (#site-live): the slider's value, the cell's read-out lines and its colour-bar ranges.
(function () {
  "use strict";
  var uid = 0;

  function id(el, prefix) {
    if (!el.id) el.id = prefix + "-" + (++uid);
    return el.id;
  }

  function set(el, name, value) {
    if (value === null) {
      if (el.hasAttribute(name)) el.removeAttribute(name);
    } else if (el.getAttribute(name) !== value) {
      el.setAttribute(name, value);
    }
  }

  function text(el) {
    return el ? el.textContent.replace(/\s+/g, " ").trim() : "";
  }

  // -- controls ---------------------------------------------------------------

  function labelOf(widget) {
    return text(widget.querySelector(":scope > .widget-label, :scope > label"));
  }

  function fixSlider(widget) {
    var handle = widget.querySelector("[role=slider]");
    if (!handle) return;
    var name = labelOf(widget) || "slider";
    var readout = widget.querySelector(".widget-readout");
    var target = widget.querySelector(".noUi-target, .slider");
    var disabled = !!(target && target.hasAttribute("disabled")) || widget.classList.contains("mod-disabled");
    set(handle, "aria-label", name);
    if (readout && text(readout)) set(handle, "aria-valuetext", text(readout));
    set(handle, "tabindex", disabled ? "-1" : "0");
    set(handle, "aria-disabled", disabled ? "true" : null);
    if (readout) {
      // an editable read-out is a text box named after its slider; a disabled one is plain text
      set(readout, "aria-label", disabled ? null : name + " (type a value)");
      if (disabled) {
        set(readout, "contenteditable", "false");
        set(readout, "tabindex", "-1");
        set(readout, "role", null);
      } else {
        set(readout, "role", readout.isContentEditable ? "textbox" : null);
      }
    }
  }

  function fixControl(widget) {
    var name = labelOf(widget);
    if (!name) return;
    widget.querySelectorAll("select, input, button, [role=button], [role=checkbox]").forEach(function (el) {
      var own = text(el) || el.getAttribute("aria-label") || (el.labels && el.labels.length && text(el.labels[0]));
      if (!own) set(el, "aria-label", name);
      if (el.disabled) set(el, "aria-disabled", "true");
    });
    var group = widget.querySelector(".widget-toggle-buttons, [role=radiogroup]");
    if (group) set(group, "aria-label", name);
  }

  // -- 3D views ---------------------------------------------------------------

  function captionOf(box) {
    var view = box.closest(".geomlib-view");
    return view && view.querySelector(".geomlib-alt");
  }

  function fixView(box) {
    var view = box.closest(".geomlib-view");
    var title = view ? text(view.querySelector(".widget-html-content b")) : "";
    set(box, "tabindex", "0");
    set(box, "role", "application");
    set(box, "aria-roledescription", "3D view");
    set(box, "aria-label", "3D view" + (title ? " of " + title : ""));
    var described = [];
    var caption = captionOf(box);
    if (caption) described.push(id(caption, "site-alt"));
    var cell = box.closest(".jp-Cell") || document;
    var keys = cell.querySelector("p.site-view-keys");
    if (keys) described.push(id(keys, "site-keys"));
    set(box, "aria-describedby", described.join(" ") || null);
    // the picture pythreejs freezes a view into stands in for the canvas: the box names it
    box.querySelectorAll("img").forEach(function (img) { set(img, "alt", ""); });
    if (!box.dataset.siteKeys) {
      box.dataset.siteKeys = "1";
      box.addEventListener("keydown", onViewKey, true);
      // a view pythreejs froze into a picture comes back to life when it gets focus
      box.addEventListener("focus", function () {
        var img = box.querySelector("img");
        if (img) img.dispatchEvent(new MouseEvent("mouseover", {bubbles: true}));
      });
    }
  }

  function drag(canvas, dx, dy, pan) {
    var r = canvas.getBoundingClientRect();
    var x = r.left + r.width / 2, y = r.top + r.height / 2;
    var opts = function (px, py) {
      return {bubbles: true, cancelable: true, clientX: px, clientY: py, screenX: px, screenY: py,
              button: 0, buttons: 1, ctrlKey: !!pan, view: window};
    };
    canvas.dispatchEvent(new MouseEvent("mousedown", opts(x, y)));
    document.dispatchEvent(new MouseEvent("mousemove", opts(x + dx, y + dy)));
    document.dispatchEvent(new MouseEvent("mouseup", opts(x + dx, y + dy)));
  }

  function wheel(canvas, delta) {
    var event = new Event("mousewheel", {bubbles: true, cancelable: true});
    Object.defineProperty(event, "wheelDelta", {value: delta});
    canvas.dispatchEvent(event);
  }

  function onViewKey(event) {
    var box = event.currentTarget;
    var canvas = box.querySelector("canvas");
    var step = 24, moves = {ArrowLeft: [-step, 0], ArrowRight: [step, 0], ArrowUp: [0, -step], ArrowDown: [0, step]};
    var handled = true;
    if (!canvas) {
      handled = false;
    } else if (moves[event.key]) {
      drag(canvas, moves[event.key][0], moves[event.key][1], event.shiftKey);
    } else if (event.key === "+" || event.key === "=") {
      wheel(canvas, 120);
    } else if (event.key === "-" || event.key === "_") {
      wheel(canvas, -120);
    } else if (event.key === "0") {
      resetView(box);
    } else {
      handled = false;
    }
    if (handled) {
      event.preventDefault();
      event.stopPropagation();  // the orbit controls' own arrow keys would pan as well
    }
  }

  // the renderer views by their element, through the page's widget manager (for reset)
  var managers = [];

  function resetView(box) {
    managers.forEach(function (manager) {
      Object.keys(manager._models || {}).forEach(function (mid) {
        manager.get_model(mid).then(function (model) {
          if (!model || model.get("_view_name") !== "RendererView") return;
          Object.keys(model.views || {}).forEach(function (k) {
            model.views[k].then(function (v) {
              if (v.el !== box || !v.controls) return;
              v.controls.forEach(function (c) {
                if (c.reset) { c.reset(); c.dispatchEvent({type: "end"}); }
              });
            });
          });
        });
      });
    });
  }

  document.addEventListener("DOMContentLoaded", function () {
    var embed = Array.prototype.find.call(document.scripts, function (s) { return /embed-amd\.js$/.test(s.src); });
    if (!embed) return;
    embed.addEventListener("load", function () {
      require(["@jupyter-widgets/html-manager"], function (htmlManager) {
        var proto = htmlManager.HTMLManager.prototype;
        var setState = proto.set_state;
        proto.set_state = function () {
          if (managers.indexOf(this) < 0) managers.push(this);
          return setState.apply(this, arguments);
        };
      });
    });
  });

  // -- announcements ------------------------------------------------------------

  var live = null;
  var pending = null;

  function announce(message) {
    if (!live || !message) return;
    // a new text node each time: screen readers announce additions to a polite region
    live.textContent = "";
    setTimeout(function () { live.textContent = message; }, 50);
  }

  function describeCell(area, widget) {
    var parts = [];
    var name = labelOf(widget), readout = text(widget.querySelector(".widget-readout"));
    if (name) parts.push(name + " " + readout + ".");
    area.querySelectorAll(".widget-html-content").forEach(function (el) {
      if (el.closest(".geomlib-view") || el.closest(".widget-slider")) return;
      var t = text(el);
      if (t) parts.push(t);
    });
    area.querySelectorAll(".geomlib-view").forEach(function (view) {
      var bar = view.querySelector(".geomlib-colorbar");
      if (!bar || !bar.getClientRects().length) return;
      var lo = text(bar.querySelector(".geomlib-vmin")), hi = text(bar.querySelector(".geomlib-vmax"));
      var label = text(bar.querySelector(".geomlib-label"));
      if (lo && hi) parts.push("Colour " + (label ? label + " " : "") + "from " + lo + " to " + hi + ".");
      else if (text(bar)) parts.push(text(bar) + ".");
    });
    return parts.join(" ");
  }

  function onSliderChange(handle) {
    var widget = handle.closest(".widget-slider");
    var area = handle.closest(".jp-OutputArea") || document.body;
    if (!widget || handle.getAttribute("aria-disabled") === "true") return;
    clearTimeout(pending);
    // after the states script has set the read-out and the views
    pending = setTimeout(function () { announce(describeCell(area, widget)); }, 400);
  }

  // -- wiring -------------------------------------------------------------------

  function fixAll(root) {
    root.querySelectorAll(".widget-slider").forEach(fixSlider);
    root.querySelectorAll(".widget-dropdown, .widget-toggle-buttons, .widget-checkbox, .widget-text, .widget-radio")
      .forEach(fixControl);
    root.querySelectorAll(".geomlib-canvas").forEach(fixView);
  }

  var scheduled = false;
  function schedule() {
    if (scheduled) return;
    scheduled = true;
    requestAnimationFrame(function () { scheduled = false; fixAll(document); });
  }

  // nbconvert makes every cell's input and output a Tab stop, so that a reader can scroll one
  // that is wider than the page; only those that are wider stay Tab stops (about 2,200 stops
  // a site otherwise, before the first slider)
  function trimTabStops() {
    document.querySelectorAll(".jp-Cell-inputWrapper[tabindex], .jp-OutputArea-output[tabindex]").forEach(
      function (el) {
        var scrolls = Array.prototype.some.call(el.querySelectorAll("*"), function (child) {
          return child.scrollWidth > child.clientWidth + 1 && /auto|scroll/.test(getComputedStyle(child).overflowX);
        }) || el.scrollWidth > el.clientWidth + 1;
        if (!scrolls) el.removeAttribute("tabindex");
      });
  }

  window.addEventListener("load", function () {
    if (window.MathJax && MathJax.Hub) MathJax.Hub.Queue(trimTabStops);
    else trimTabStops();
  });

  document.addEventListener("DOMContentLoaded", function () {
    live = document.getElementById("site-live");
    fixAll(document);
    new MutationObserver(function (records) {
      var again = false;
      records.forEach(function (r) {
        if (r.type === "attributes" && r.attributeName === "aria-valuenow") {
          var handle = r.target;
          if (handle.getAttribute("role") === "slider" && document.activeElement === handle) onSliderChange(handle);
        }
        if (r.type === "childList" || r.type === "characterData" ||
            (r.type === "attributes" && /^(disabled|class|contenteditable)$/.test(r.attributeName))) again = true;
      });
      if (again) schedule();
    }).observe(document.body, {subtree: true, childList: true, characterData: true, attributes: true,
                               attributeFilter: ["aria-valuenow", "disabled", "class", "contenteditable"]});
  });
  window.siteA11y = {fixAll: fixAll, describeCell: describeCell};  // for the browser test
})();
