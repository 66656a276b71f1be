// The web viewer's controls for a bake with light groups (IRBAKE_lightmap_scenarios): one slider per layer (its
// weight, 0 to 2, the same on R, G and B), with exactly two layers a day/night slider t that sets them to 1 − t
// and t, and a button per stored scenario. A panel over the canvas (the canvas's pixels are the render alone);
// `controls` is showBakedScene's: every change renders again.
export function addScenarioSliders(controls, parent = document.body) {
  const panel = document.createElement('div');
  panel.style.cssText = 'position:fixed;top:8px;left:8px;padding:6px 8px;background:rgba(0,0,0,0.6);color:#eee;' +
                        'font:12px sans-serif;border-radius:4px';
  const grey = w => (Array.isArray(w) ? (w[0] + w[1] + w[2]) / 3 : w);
  const sliders = new Map();
  const row = (label, value, onInput) => {
    const line = document.createElement('label');
    line.style.cssText = 'display:block;white-space:nowrap';
    const input = Object.assign(document.createElement('input'), { type: 'range', min: 0, max: 2, step: 0.01, value });
    const shown = document.createElement('span');
    shown.textContent = Number(value).toFixed(2);
    input.addEventListener('input', () => { shown.textContent = Number(input.value).toFixed(2); onInput(Number(input.value)); });
    line.append(`${label} `, input, ' ', shown);
    panel.append(line);
    return { input, shown };
  };
  const refresh = () => {
    for (const [name, w] of Object.entries(controls.weights())) {
      const s = sliders.get(name);
      s.input.value = grey(w);
      s.shown.textContent = grey(w).toFixed(2);
    }
  };
  for (const [name, w] of Object.entries(controls.weights()))
    sliders.set(name, row(name, grey(w), v => controls.setWeights({ [name]: v })));
  if (controls.layers.length === 2) {
    const [a, b] = controls.layers;
    const fade = row(`${a} ⇄ ${b}`, 0.5, t => { controls.setWeights({ [a]: 1 - t, [b]: t }); refresh(); });
    fade.input.max = 1;
  }
  for (const name of controls.scenarios) {
    const button = Object.assign(document.createElement('button'), { textContent: name });
    button.addEventListener('click', () => { controls.useScenario(name); refresh(); });
    panel.append(button, ' ');
  }
  parent.append(panel);
  return panel;
}
