"""The HTML and JavaScript around meshcat's viewer in a run page.

The page inflates the embedded files (``freefloat_asset``), replays the command packets
(``freefloat_command``) with every ``freefloat-asset:<i>`` placeholder replaced by file ``i``,
frames the camera, and shows play/pause, a time slider, the clock and the run's events at the
bottom of the picture. The address's fragment can set the view for screenshots:
``#t=1.5`` (pause at t = 1.5 s of simulated time), ``#hide`` (hide the run, keep grid and
background). When all is drawn, ``document.body.dataset.freefloat`` is ``"ready"``.
"""

PAGE = """<!DOCTYPE html>
<html>
<head><meta charset="utf-8"><title>{title}</title>
<style>
body {{margin: 0; font-family: sans-serif;}}
#meshcat-pane {{width: 100vw; height: 100vh; overflow: hidden;}}
#freefloat-controls {{position: fixed; left: 0; right: 0; bottom: 0; display: flex; gap: 0.8em;
  align-items: center; padding: 0.4em 0.8em; background: rgba(255, 255, 255, 0.8); font-size: 14px;}}
#freefloat-time {{flex: 1;}}
#freefloat-events span.passed {{font-weight: bold; color: #b00000;}}
</style>
</head>
<body>
<div id="meshcat-pane"></div>
<div id="freefloat-controls">
<button id="freefloat-play">pause</button>
<input id="freefloat-time" type="range" min="0" max="1" step="any" value="0" list="freefloat-ticks">
<datalist id="freefloat-ticks"></datalist>
<span id="freefloat-clock"></span>
<span id="freefloat-events"></span>
</div>
<script>
{viewer_js}
</script>
<script>
var viewer = new MeshCat.Viewer(document.getElementById("meshcat-pane"));
const FREEFLOAT = {settings};
const FREEFLOAT_ASSETS = [];
const FREEFLOAT_COMMANDS = [];
function freefloat_asset(kind, b64) {{ FREEFLOAT_ASSETS.push([kind, b64]); }}
function freefloat_command(b64) {{ FREEFLOAT_COMMANDS.push(b64); }}
function freefloat_bytes(b64) {{ return Uint8Array.from(atob(b64), (c) => c.charCodeAt(0)); }}
async function freefloat_inflate([kind, b64]) {{
  const stream = new Blob([freefloat_bytes(b64)]).stream().pipeThrough(new DecompressionStream("gzip"));
  const bytes = new Uint8Array(await new Response(stream).arrayBuffer());
  return kind === "text" ? new TextDecoder().decode(bytes) : bytes;
}}
function freefloat_resolve(x, assets) {{
  if (typeof x === "string" && x.startsWith("freefloat-asset:")) return assets[Number(x.slice(16))];
  if (x && typeof x === "object" && !ArrayBuffer.isView(x)) {{
    for (const key of Object.keys(x)) x[key] = freefloat_resolve(x[key], assets);
  }}
  return x;
}}
function freefloat_camera() {{
  const c = FREEFLOAT.camera, three = (p) => [p[0], p[2], -p[1]];
  viewer.camera.position.set(...three(c.position));
  viewer.controls.target.set(...three(c.target));
  viewer.camera.near = c.radius / 200;
  viewer.camera.far = 50 * c.radius;
  viewer.camera.updateProjectionMatrix();
  viewer.controls.update();
}}
function freefloat_controls() {{
  const anim = viewer.animator, slider = document.getElementById("freefloat-time");
  const button = document.getElementById("freefloat-play"), clock = document.getElementById("freefloat-clock");
  const events = document.getElementById("freefloat-events"), ticks = document.getElementById("freefloat-ticks");
  slider.max = FREEFLOAT.duration;
  for (const [time, label] of FREEFLOAT.events) {{
    const span = document.createElement("span");
    span.textContent = label + " at t = " + time.toFixed(3) + " s ";
    span.dataset.time = time;
    events.appendChild(span);
    const tick = document.createElement("option");
    tick.value = time - FREEFLOAT.t0;
    ticks.appendChild(tick);
  }}
  const now = () => anim.actions.reduce((m, a) => Math.max(m, a.time), 0);
  button.onclick = () => {{ if (anim.playing) anim.pause(); else anim.play(); }};
  slider.oninput = () => {{ anim.pause(); anim.seek(Number(slider.value)); }};
  (function tick() {{
    const time = now();
    slider.value = time;
    button.textContent = anim.playing ? "pause" : "play";
    clock.textContent = "t = " + (FREEFLOAT.t0 + time).toFixed(3) + " s";
    for (const span of events.children) span.className = FREEFLOAT.t0 + time >= Number(span.dataset.time) ? "passed" : "";
    requestAnimationFrame(tick);
  }})();
}}
function freefloat_fragment() {{
  const options = new URLSearchParams(location.hash.slice(1));
  if (options.has("t")) {{
    viewer.animator.pause();
    viewer.animator.seek(Number(options.get("t")) - FREEFLOAT.t0);
  }}
  if (options.has("hide")) viewer.scene_tree.find(["meshcat", "freefloat"]).object.visible = false;
  viewer.set_dirty();
}}
{commands}
(async () => {{
  const assets = await Promise.all(FREEFLOAT_ASSETS.map(freefloat_inflate));
  const handle = viewer.handle_command.bind(viewer);
  viewer.handle_command = (command) => handle(freefloat_resolve(command, assets));
  for (const b64 of FREEFLOAT_COMMANDS) viewer.handle_command_bytearray(freefloat_bytes(b64));
  freefloat_camera();
  freefloat_controls();
  freefloat_fragment();
  document.body.dataset.freefloat = "ready";
}})();
</script>
</body>
</html>
"""
