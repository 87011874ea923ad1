"""The explorer in a Jupyter notebook: the page's controls (controls.py) as ipywidgets, the same
session and render loop (session.py, loop.py), the picture in an Image widget.

    from pyjulia4d.app.explore.notebook import Explorer
    Explorer()                       # the built-in scene; Explorer("scene.toml") or a Scene

Sliders send requests while they move (previews); a quarter of a second after the last
change the picture is refined to the scene's full size.  Buttons orbit the camera, turn it
through w and zoom (geometry/navigate.py), save the scene, render it to a file and keep
keyframes, as the page's do.  Needs ipywidgets (``pip install ipywidgets``).
"""
from __future__ import annotations

import os
import threading
from pathlib import Path
from typing import Any

from pyjulia4d.app.explore import controls
from pyjulia4d.app.explore.session import Session
from pyjulia4d.scene.checks import SceneError
from pyjulia4d.scene.model import Scene

REST_SECONDS = 0.25   # after the last change, the picture is refined
STEP_DEGREES = 10.0   # one press of an orbit or w-turn button
ZOOM_STEP = 1.25


def _scene(scene: Scene | str | Path | None) -> Scene:
    if scene is None:
        return Scene.from_dict({})
    if isinstance(scene, Scene):
        return scene
    if not isinstance(scene, (str, os.PathLike)):
        raise SceneError("scene", f"expected None, a pyjulia4d.Scene or a scene file's path, got "
                                  f"{type(scene).__name__}")
    return Scene.from_toml(scene)


class Explorer:
    """An ipywidgets view of a scene (see the module's docstring); ``device`` as render's
    --device; files are written in ``folder``."""

    def __init__(self, scene: Scene | str | Path | None = None, device: Any = None, folder: str | Path = ".") -> None:
        from pyjulia4d.app.explore.run import check_folder, device_renderer, warm

        folder = check_folder(folder)   # the arguments before ipywidgets, whose import is slow
        start = _scene(scene)
        import ipywidgets as w

        render = device_renderer(device)
        scene = warm(start, render)
        self.image = w.Image(format="png", layout=w.Layout(width="640px"))
        self.facts = w.HTML()
        self.message = w.HTML()
        self.widgets: dict[str, Any] = {}
        self._quiet = False   # values set by the session, not by the user
        self._rest: threading.Timer | None = None
        values = controls.form_values(scene)
        boxes = []
        for title, group in controls.GROUPS:
            rows = []
            for c in group:
                for name in c.names():
                    widget = self._widget(w, c, name, values[name], scene)
                    widget.observe(self._changed, names="value")
                    self.widgets[name] = widget
                    rows.append(widget)
            boxes.append(w.VBox(rows))
        tabs = w.Tab(children=boxes)
        for i, (title, _) in enumerate(controls.GROUPS):
            tabs.set_title(i, title)
        moves = [("◀", "orbit", {"yaw": -STEP_DEGREES}), ("▶", "orbit", {"yaw": STEP_DEGREES}),
                 ("▲", "orbit", {"pitch": STEP_DEGREES}), ("▼", "orbit", {"pitch": -STEP_DEGREES}),
                 ("w−", "turn_w", {"degrees": -STEP_DEGREES}), ("w+", "turn_w", {"degrees": STEP_DEGREES}),
                 ("zoom in", "zoom", {"factor": 1 / ZOOM_STEP}), ("zoom out", "zoom", {"factor": ZOOM_STEP})]
        buttons = []
        for label, op, args in moves:
            b = w.Button(description=label, layout=w.Layout(width="auto"))
            b.on_click(lambda _, op=op, args=args: self.session.handle({"op": op, **args}))
            buttons.append(b)
        self.name = w.Text(value="explore.png", description="file")
        save = w.Button(description="Save scene")
        save.on_click(lambda _: self.session.handle({"op": "save_scene",
                                                     "name": Path(self.name.value).stem + ".toml"}))
        render_b = w.Button(description="Render to file")
        render_b.on_click(lambda _: self.session.handle({"op": "render_file", "name": self.name.value}))
        key = w.Button(description="Add keyframe")
        key.on_click(lambda _: self.session.handle({"op": "keyframe"}))
        anim = w.Button(description="Save animation")
        anim.on_click(lambda _: self.session.handle({"op": "save_animation",
                                                     "name": Path(self.name.value).stem + "-animation.toml"}))
        self.view = w.HBox([w.VBox([self.image, w.HBox(buttons), self.message, self.facts,
                                    w.HBox([self.name, save, render_b, key, anim])]), tabs])
        self.session = Session(scene, render, folder, self._emit)
        self.session.start()

    @staticmethod
    def _widget(w: Any, c: controls.Control, name: str, value: str, scene: Scene) -> Any:
        label = name.replace(c.key, c.label)
        style = {"description_width": "120px"}
        if c.widget == "select":
            return w.Dropdown(options=controls.options(c, scene), value=value, description=label, style=style)
        if c.widget == "text":   # sent when typed out (Enter or leaving the field), not at each key
            return w.Text(value=value, description=label, style=style, continuous_update=False)
        x = float(value)
        integer = c.step == 1 and x.is_integer()
        number = int(x) if integer else x
        if c.slider:   # the span widened to hold the scene's value
            cls = w.IntSlider if integer else w.FloatSlider
            return cls(value=number, min=min(c.lo, x), max=max(c.hi, x), step=c.step, description=label, style=style,
                       continuous_update=True, readout_format="d" if integer else ".4g")
        cls = w.IntText if integer else w.FloatText
        return cls(value=number, description=label, style=style)

    def _changed(self, change: dict) -> None:
        if self._quiet:
            return
        name = next(n for n, wd in self.widgets.items() if wd is change["owner"])
        values = {name: str(change["new"])}
        if name == "fractal.algebra":   # the algebra's functions (the page does the same)
            from pyjulia4d.fractal.registry import FUNCTIONS_OF

            f = self.widgets["fractal.function"]
            names = list(FUNCTIONS_OF[change["new"]])
            keep = f.value if f.value in names else names[0]
            self._quiet = True
            try:
                f.options, f.value = names, keep
            finally:
                self._quiet = False
            values["fractal.function"] = keep
        self.session.handle({"op": "set", "values": values, "moving": True})
        if self._rest is not None:
            self._rest.cancel()
        self._rest = threading.Timer(REST_SECONDS, lambda: self.session.handle({"op": "refine"}))
        self._rest.daemon = True
        self._rest.start()

    def _emit(self, message: dict, data: bytes | None) -> None:
        kind = message.get("type")
        if kind == "frame" and data is not None:
            self.image.value = data
            f = message["facts"]
            self.facts.value = "<br>".join(f"<b>{k}</b>: {v}" for k, v in f.items())
        elif kind == "values":
            self._quiet = True
            try:
                for name, text in message["values"].items():
                    if name in self.widgets:
                        wd = self.widgets[name]
                        wd.value = text if isinstance(wd.value, str) else type(wd.value)(float(text))
            finally:
                self._quiet = False
        elif kind == "error":
            self.message.value = f"<span style='color:#c33'>{_escape(message['message'])}</span>"
        elif kind in ("status", "progress", "keyframes"):
            text = message.get("message") or (f"rendering {message['name']}: {100 * message['done']:.0f} %"
                                               if kind == "progress" else f"{message['count']} keyframes")
            self.message.value = _escape(text)

    def _ipython_display_(self) -> None:
        from IPython.display import display

        display(self.view)

    def close(self) -> None:
        self.session.close()


def _escape(text: str) -> str:
    import html

    return html.escape(text)
