// JointPlot: live traces of chosen joints over the last `span` seconds of
// server time, on a 2D canvas. The operator picks the joints with check boxes.
const COLOURS = ['#4fa3ff', '#f5a623', '#3ecf8e', '#ff6bcb', '#c4a7ff', '#ffd166', '#66e0ff', '#ff8a65'];

export class JointPlot {
  constructor(canvas, checkboxes, dofNames, joints, span = 10) {
    this.canvas = canvas;
    this.ctx = canvas.getContext('2d');
    this.span = span;
    this.names = dofNames;
    this.samples = [];  // [t, q[]]
    this.chosen = new Set(JointPlot.defaultChoice(joints));
    checkboxes.replaceChildren();
    dofNames.forEach((name, i) => {
      const label = document.createElement('label');
      const box = document.createElement('input');
      box.type = 'checkbox';
      box.checked = this.chosen.has(i);
      box.dataset.dof = String(i);
      box.addEventListener('change', () => { box.checked ? this.chosen.add(i) : this.chosen.delete(i); this.draw(); });
      label.append(box, ' ' + name);
      checkboxes.append(label);
    });
  }

  // Up to three revolute dofs with limits (a pan, a tilt, an arm's shoulder),
  // else the first three dofs.
  static defaultChoice(joints) {
    const limited = [];
    for (const j of joints) {
      j.dofs.forEach((d, k) => { if (!j.mimic && d.lower !== null && d.upper !== null) limited.push(j.dof_offset + k); });
    }
    const all = joints.flatMap((j) => j.dofs.map((d, k) => j.dof_offset + k));
    return (limited.length ? limited : all).slice(0, 3);
  }

  add(t, q) {
    if (this.samples.length && t <= this.samples[this.samples.length - 1][0]) return;
    this.samples.push([t, q]);
    const oldest = t - this.span;
    let drop = 0;
    while (drop < this.samples.length && this.samples[drop][0] < oldest) ++drop;
    if (drop) this.samples.splice(0, drop);
  }

  draw() {
    const { ctx, canvas } = this;
    const w = canvas.width, h = canvas.height;
    ctx.clearRect(0, 0, w, h);
    const chosen = [...this.chosen].sort((a, b) => a - b);
    this.lastDrawn = {};
    if (!this.samples.length || !chosen.length) return;
    let lo = Infinity, hi = -Infinity;
    for (const [, q] of this.samples) for (const i of chosen) { lo = Math.min(lo, q[i]); hi = Math.max(hi, q[i]); }
    if (hi - lo < 0.2) { const m = (hi + lo) / 2; lo = m - 0.1; hi = m + 0.1; }
    const tEnd = this.samples[this.samples.length - 1][0], t0 = tEnd - this.span;
    const X = (t) => 40 + (w - 50) * (t - t0) / this.span;
    const Y = (v) => h - 14 - (h - 24) * (v - lo) / (hi - lo);
    ctx.strokeStyle = '#2a3340'; ctx.fillStyle = '#8b96a5'; ctx.font = '10px sans-serif';
    for (const v of [lo, (lo + hi) / 2, hi]) {
      ctx.beginPath(); ctx.moveTo(40, Y(v)); ctx.lineTo(w - 10, Y(v)); ctx.stroke();
      ctx.fillText(v.toFixed(2), 2, Y(v) + 3);
    }
    ctx.fillText(`last ${this.span} s`, w - 60, h - 2);
    chosen.forEach((i, n) => {
      ctx.strokeStyle = COLOURS[n % COLOURS.length];
      ctx.beginPath();
      this.samples.forEach(([t, q], k) => (k ? ctx.lineTo(X(t), Y(q[i])) : ctx.moveTo(X(t), Y(q[i]))));
      ctx.stroke();
      ctx.fillStyle = COLOURS[n % COLOURS.length];
      const v = this.samples[this.samples.length - 1][1][i];
      ctx.fillText(`${this.names[i]} ${v.toFixed(3)}`, 44 + 110 * n, 10);
      this.lastDrawn[this.names[i]] = v;
    });
  }
}
