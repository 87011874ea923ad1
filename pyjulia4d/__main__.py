"""``python -m pyjulia4d``."""
from pyjulia4d.app.cli import main

if __name__ == "__main__":
    raise SystemExit(main())
