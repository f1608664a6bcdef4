/* crowdvib's only script in a report (issue 38): it moves the pictures its figures already show.
   The page's Content-Security-Policy allows exactly this text, by its SHA-256; it fetches
   nothing and reads only the data blocks crowdvib wrote beside each picture. Without it the
   pictures stay as they are: a still of the same content. */
(function () {
  "use strict";
  var NS = "http://www.w3.org/2000/svg";

  function polyline(xs, ys) {
    var d = "";
    for (var i = 0; i < xs.length; i++) {
      d += (i ? "L" : "M") + xs[i].toFixed(1) + " " + ys[i].toFixed(1);
    }
    return d;
  }

  function element(name, attributes, parent) {
    var node = document.createElement(name);
    for (var key in attributes) { node.setAttribute(key, attributes[key]); }
    parent.appendChild(node);
    return node;
  }

  /* Play/pause, a slider over the steps and a label; draw(step) shows one step. */
  function controls(box, steps, rate, draw) {
    var bar = element("div", {"class": "cv-controls"}, box);
    var button = element("button", {"type": "button", "class": "cv-play"}, bar);
    var slider = element("input", {"type": "range", "min": "0", "max": String(steps - 1),
                                   "step": "1", "value": "0", "class": "cv-slider",
                                   "aria-label": box.getAttribute("data-cv-slider")}, bar);
    var label = element("span", {"class": "cv-label"}, bar);
    var timer = null;
    function show(step) {
      slider.value = String(step);
      label.textContent = draw(step);
      box.setAttribute("data-cv-step", String(step));
    }
    function pause() {
      clearInterval(timer); timer = null;
      button.textContent = "Play"; box.setAttribute("data-cv-playing", "no");
    }
    function play() {
      timer = setInterval(function () { show((Number(slider.value) + 1) % steps); },
                          1000 / rate);
      button.textContent = "Pause"; box.setAttribute("data-cv-playing", "yes");
    }
    button.addEventListener("click", function () { if (timer) { pause(); } else { play(); } });
    slider.addEventListener("input", function () { if (timer) { pause(); } show(Number(slider.value)); });
    pause();
    show(0);
  }

  /* Mode shapes: every lane's line y = y0 + dy cos(phase). */
  function modes(box, data) {
    var lines = box.querySelectorAll("path[data-cv-line]");
    controls(box, data.steps, data.rate, function (step) {
      var phase = 2 * Math.PI * step / data.steps, c = Math.cos(phase);
      for (var i = 0; i < lines.length; i++) {
        var ids = lines[i].getAttribute("data-cv-line").split(" ");
        var panel = data.panels[Number(ids[0])], dy = panel.lanes[Number(ids[1])];
        var ys = dy.map(function (v) { return panel.y0 + v * c; });
        lines[i].setAttribute("d", polyline(panel.x, ys));
      }
      box.setAttribute("data-cv-phase", String(Math.round(360 * step / data.steps)));
      return "phase " + Math.round(360 * step / data.steps) + "°";
    });
  }

  /* With HSI, walker k's MSD motion at frame `step` [px]: its code there (one character a
     frame from its first on the deck) as an integer times px; 0 where it has none. */
  function lifted(m, k, step) {
    var c = m.codes[k].charAt(step - m.first[k]);
    return c ? m.px * (m.alphabet.indexOf(c) - m.zero) : 0;
  }

  /* The crossing: the deck's deflection from the modal coordinates, the walkers where their
     arrival time and speed put them (with HSI lifted by their MSD's motion, else bobbing at
     their step frequency), the cursor on the acceleration traces. */
  function replay(box, data) {
    var deck = box.querySelector("path[data-cv-deck]");
    var cursors = box.querySelectorAll("line[data-cv-cursor]");
    var layer = box.querySelector("g[data-cv-walkers]");
    var plan = box.querySelector("g[data-cv-plan]");
    var w = data.walkers, nm = data.shapes.length, dots = [], marks = [];
    box.querySelector("g.cv-still").setAttribute("display", "none");   /* the still's walkers */
    for (var k = 0; k < w.t_on.length; k++) {
      dots.push(layer.appendChild(document.createElementNS(NS, "circle")));
      marks.push(plan.appendChild(document.createElementNS(NS, "circle")));
    }
    function deckY(q) {
      return data.x.map(function (_, i) {
        var y = data.y0;
        for (var j = 0; j < nm; j++) { y += data.shapes[j][i] * q[j]; }
        return y;
      });
    }
    function interpolate(xs, ys, x) {
      if (x <= xs[0]) { return ys[0]; }
      for (var i = 1; i < xs.length; i++) {
        if (x <= xs[i]) { return ys[i - 1] + (ys[i] - ys[i - 1]) * (x - xs[i - 1]) / (xs[i] - xs[i - 1]); }
      }
      return ys[ys.length - 1];
    }
    controls(box, data.q.length, data.rate, function (step) {
      var t = data.t0 + step / data.rate, q = data.q[step], ys = deckY(q), on = 0;
      deck.setAttribute("d", polyline(data.x, ys));
      for (var k = 0; k < dots.length; k++) {
        var here = w.t_on[k] <= t && t < w.t_off[k];
        var x = w.x_start[k] + w.velocity[k] * (t - w.arrival[k]);
        var px = data.ax + data.bx * x;
        var bob = data.msd ? lifted(data.msd, k, step)
          : data.bob * Math.sin(2 * Math.PI * w.step_frequency[k] * (t - w.arrival[k]));
        dots[k].setAttribute("r", here ? "2.5" : "0");
        dots[k].setAttribute("cx", px.toFixed(1));
        dots[k].setAttribute("cy", (interpolate(data.x, ys, px) - data.lift - bob).toFixed(1));
        dots[k].setAttribute("fill", data.colours[w.velocity[k] >= 0 ? 0 : 1]);
        marks[k].setAttribute("r", here ? "2" : "0");
        marks[k].setAttribute("cx", px.toFixed(1));
        marks[k].setAttribute("cy", (data.plan_y0 + data.plan_by * w.lateral[k]).toFixed(1));
        marks[k].setAttribute("fill", dots[k].getAttribute("fill"));
        if (here) { on += 1; }
      }
      var cx = (data.trace_x0 + (t - data.t0) * data.trace_bx).toFixed(1);
      for (var i = 0; i < cursors.length; i++) {
        cursors[i].setAttribute("x1", cx); cursors[i].setAttribute("x2", cx);
      }
      box.setAttribute("data-cv-time", t.toFixed(2));
      box.setAttribute("data-cv-on-deck", String(on));
      return "t = " + t.toFixed(2) + " s, " + on + " on the deck";
    });
  }

  var boxes = document.querySelectorAll(".cv-anim");
  for (var i = 0; i < boxes.length; i++) {
    var data = JSON.parse(boxes[i].querySelector("script.cv-data").textContent);
    (data.kind === "modes" ? modes : replay)(boxes[i], data);
    boxes[i].setAttribute("data-cv-ready", "yes");
  }
})();
