// Injected after the page's script by tests/suite/view.rs: drives the page as a user
// does (the setup selector, the check boxes, a drag and the wheel) and writes what it
// saw, read from the page's `window.__inspc` hook and its canvas, as JSON in a
// `pre` element of id `inspc-test` that `--dump-dom` shows.
(() => {
  const out = { setups: [], markers: [] };
  try {
    const $ = (id) => document.getElementById(id);
    const canvas = $("view"), sel = $("setup");
    const ctx = canvas.getContext("2d");
    const pick = (k) => { sel.value = String(k); sel.dispatchEvent(new Event("change")); };
    const rot = (r, p) => [0, 1, 2].map((i) => r[i][0] * p[0] + r[i][1] * p[1] + r[i][2] * p[2]);
    SCENE.setups.forEach((s, k) => {
      pick(k);
      const held = $("held");
      let m = [0, 0, 0], n = 0;
      for (const g of s.groups) for (const [p] of g.touches) {
        const v = rot(s.rotation, SCENE.points[p].n);
        m = m.map((x, i) => x + v[i]); n++;
      }
      out.setups.push({
        camera: window.__inspc.camera,
        mean_normal: m.map((x) => x / Math.max(n, 1)),
        held: held.textContent,
        held_fits: held.scrollWidth <= held.clientWidth + 1 && getComputedStyle(held).textOverflow !== "ellipsis",
      });
    });
    for (const id of ["showPath", "showProbe", "showCone"]) { $(id).checked = false; $(id).dispatchEvent(new Event("change")); }
    SCENE.setups.forEach((s, k) => {
      pick(k);
      for (const mk of window.__inspc.markers) {
        const px = ctx.getImageData(Math.floor(mk.x), Math.floor(mk.y), 1, 1).data;
        out.markers.push({ setup: k, x: mk.x, y: mk.y, nz: mk.nz, hidden: mk.hidden, color: mk.color, pixel: [px[0], px[1], px[2]] });
      }
    });
    pick(0);
    const r = canvas.getBoundingClientRect();
    const drag = (dy) => {
      const at = (y) => ({ clientX: r.left + 50, clientY: y, bubbles: true });
      canvas.dispatchEvent(new MouseEvent("mousedown", at(r.top + 200)));
      window.dispatchEvent(new MouseEvent("mousemove", at(r.top + 200 + dy)));
      window.dispatchEvent(new MouseEvent("mouseup", at(r.top + 200 + dy)));
      return window.__inspc.camera.pitch;
    };
    const wheel = (dy) => {
      canvas.dispatchEvent(new WheelEvent("wheel", { deltaY: dy, cancelable: true, bubbles: true }));
      return window.__inspc.camera.zoom;
    };
    out.drag = { up: drag(-10000), down: drag(10000), out: wheel(1e6), in: wheel(-1e6) };
    out.palette = window.__inspc.palette;
  } catch (e) {
    out.error = String(e);
  }
  const pre = document.createElement("pre");
  pre.id = "inspc-test"; pre.textContent = JSON.stringify(out);
  document.body.appendChild(pre);
})();
