// Signal plots beside the scene (uPlot): a cursor line at the timeline's time; a click moves it.
import uPlot from 'uplot';
import { decode } from './data.js';

const COLORS = ['#2f6fd6', '#e8871e', '#3d9970', '#b0413e', '#7d5ba6', '#8c6d46', '#c9609b', '#5f6b7a', '#a6a63c', '#2aa1b3', '#444', '#999'];

export function buildPlots(host, plots, jump) {
  return plots.map((p) => {
    const div = document.createElement('div');
    div.className = 'plot';
    host.appendChild(div);
    const t = decode(p.t);
    const ys = p.y.map(decode);
    const width = Math.max(host.clientWidth - 14, 240);
    let place = () => {};
    const opts = {
      title: `${p.name} (${p.unit})`,
      width, height: 170,
      scales: { x: { time: false } },
      legend: { live: false },
      cursor: { drag: { x: true, y: false } },
      series: [{ label: 't (s)' }, ...p.columns.map((c, k) => ({ label: c, stroke: COLORS[k % COLORS.length], width: 1.25 }))],
      axes: [{ label: 't (s)' }, { size: 60 }],
      hooks: { setScale: [() => place()] },
    };
    const u = new uPlot(opts, [t, ...ys], div);
    const line = document.createElement('div');
    line.className = 'cursor';
    u.over.appendChild(line);
    line.style.height = `${u.over.clientHeight}px`;
    let down = null;
    u.over.addEventListener('mousedown', (e) => { down = e.clientX; });
    u.over.addEventListener('mouseup', (e) => {
      // a click (not a zoom drag) moves the timeline
      if (down !== null && Math.abs(e.clientX - down) < 3) jump(u.posToVal(e.offsetX, 'x'));
      down = null;
    });
    let current = t[0];
    place = () => {
      const x = u.valToPos(current, 'x');
      line.style.display = x >= 0 && x <= u.over.clientWidth ? 'block' : 'none';
      line.style.left = `${x}px`;
    };
    window.addEventListener('resize', () => { u.setSize({ width: Math.max(host.clientWidth - 14, 240), height: 170 }); place(); });
    return { name: p.name, plot: u, cursor(time) { current = time; place(); } };
  });
}
