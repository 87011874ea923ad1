"""``pyjulia4d explore``: a local page that renders as you drag (server.py, page/), and the same
view in a notebook (notebook.py), both driven by one session (session.py) and its render loop
(loop.py); the controls they offer are controls.py's."""
