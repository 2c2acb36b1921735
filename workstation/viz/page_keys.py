"""Keyboard shortcuts in the survey panel (issue #13): Delete removes the selected landmark,
Ctrl+Z undoes, Ctrl+Y (or Ctrl+Shift+Z) redoes — as in every drawing program. And the mouse wheel
zooms towards the cursor, as in every map (issue #30): viser 1.1 mounts camera-controls with
``dollyToCursor`` off and has no server-side switch, so the script turns it on on the controls
viser itself exposes (``window.__viserMutable.cameraControl``, its hook for tests), again
whenever viser mounts new controls.

viser 1.1 (pinned) sends no key events to Python, so the panel's page gets a few lines of
script that press the panel's own buttons ("Delete landmark", "Undo", "Redo") of the tab they are
typed in — the same path as a click, with the same per-tab selection and the editor's lock.
Keys typed into a text field are left alone. The script is added to the page viser serves
(``index.html``) through :mod:`.serve_hook`, as :mod:`.origin_guard` refuses other sites;
no other request is touched.
"""

from __future__ import annotations

import dataclasses
import gzip

from workstation.viz.serve_hook import hook

SCRIPT = """<script>
document.addEventListener("keydown", (e) => {
  const t = e.target;
  if (t && (t.isContentEditable || ["INPUT", "TEXTAREA", "SELECT"].includes(t.tagName))) return;
  const k = e.key.toLowerCase(), mod = e.ctrlKey || e.metaKey;
  let label = null;
  if (mod && k === "z" && !e.shiftKey) label = "Undo";
  else if (mod && (k === "y" || (k === "z" && e.shiftKey))) label = "Redo";
  else if (!mod && (e.key === "Delete" || e.key === "Backspace")) label = "Delete landmark";
  if (!label) return;
  const b = [...document.querySelectorAll("button")].find((b) => b.textContent.trim() === label);
  if (b && !b.disabled) { e.preventDefault(); b.click(); }
});
setInterval(() => {
  const c = window.__viserMutable && window.__viserMutable.cameraControl;
  if (c && !c.dollyToCursor) c.dollyToCursor = true;
}, 250);
</script>"""


def with_shortcuts(html: bytes) -> bytes:
    """The page with the shortcut script before ``</body>`` (or at the end)."""
    marker = b"</body>"
    at = html.rfind(marker)
    script = SCRIPT.encode()
    return html[:at] + script + html[at:] if at >= 0 else html + script


def install() -> None:
    """Add the shortcut script to the panel's page from now on (idempotent)."""
    def wrap(process_request):
        def page(connection, request):
            resp = None if process_request is None else process_request(connection, request)
            path = request.path.partition("?")[0]
            if resp is None or path not in ("/", "/index.html") or resp.status_code != 200:
                return resp
            zipped = resp.headers.get("Content-Encoding") == "gzip"
            body = gzip.decompress(resp.body) if zipped else resp.body
            body = with_shortcuts(body)
            body = gzip.compress(body) if zipped else body
            del resp.headers["Content-Length"]
            resp.headers["Content-Length"] = str(len(body))
            return dataclasses.replace(resp, body=body)

        return page

    hook("_workstation_keys", wrap)
