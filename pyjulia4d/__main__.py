"""``python -m pyjulia4d``."""
from pyjulia4d.cli import main

if __name__ == "__main__":
    raise SystemExit(main())
