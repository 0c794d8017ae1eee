"""Stand-ins for what the reference codes import but never use on the paths our scripts run
them: `pygame` (Overcooked draws with it), `IPython` (debugging hooks in the env files),
`matplotlib` (plots), `wandb` (ACAC's optional logging), and numpy 2's removed `np.bool8`,
which gym 0.26's passive env checker names. One place for every script that imports MacroMARL,
MacDec-via-Cen or ACAC (`macromarl_traces.py`, `acac_traces.py`, the golden and trace writers,
the reference-curve and speed scripts).

Each stand-in is installed only where the real module is missing, so an environment that has
the real package keeps it. Nothing here changes what the references compute.
"""

import sys
import types


def _missing(name):
    try:
        __import__(name)
        return False
    except ImportError:
        return True


def install_pygame():
    """A `pygame` whose every name is a callable that draws nothing."""
    if not _missing("pygame"):
        return

    class Stand:
        """Any pygame name: a distinct object per name, callable, never drawn."""

        def __init__(self, name):
            self.name = name

        def __call__(self, *args, **kwargs):
            return Stand(self.name + "()")

        def __getattr__(self, name):
            return Stand(self.name + "." + name)

    names = {}
    stand_in = types.ModuleType("pygame")

    def stand(name):
        if name.startswith("__"):  # module protocol (torch's inspect asks for __file__)
            raise AttributeError(name)
        return names.setdefault(name, Stand(name))

    stand_in.__getattr__ = stand
    sys.modules["pygame"] = stand_in


def install_ipython():
    """`IPython`, `IPython.core.debugger.set_trace` and `IPython.embed`, all doing nothing."""
    if not _missing("IPython"):
        return
    ip = types.ModuleType("IPython")
    ip.core = types.ModuleType("IPython.core")
    ip.core.debugger = types.ModuleType("IPython.core.debugger")
    ip.embed = lambda *a, **k: None
    ip.core.debugger.set_trace = lambda *a, **k: None
    for name, mod in [("IPython", ip), ("IPython.core", ip.core),
                      ("IPython.core.debugger", ip.core.debugger)]:
        sys.modules[name] = mod


def install_matplotlib():
    """An empty `matplotlib` with an empty `pyplot`."""
    if not _missing("matplotlib.pyplot"):
        return
    mpl = types.ModuleType("matplotlib")
    mpl.pyplot = types.ModuleType("matplotlib.pyplot")
    sys.modules["matplotlib"] = mpl
    sys.modules["matplotlib.pyplot"] = mpl.pyplot


def install_wandb():
    """An empty `wandb` (ACAC imports it; its logging is off unless asked for)."""
    if _missing("wandb"):
        sys.modules["wandb"] = types.ModuleType("wandb")


def install_numpy_bool8():
    """`np.bool8 = np.bool_` under numpy 2 (the same type; gym 0.26's checker names it)."""
    import numpy as np

    if not hasattr(np, "bool8"):
        np.bool8 = np.bool_


def install_all():
    """Every stand-in above (each only where the real module is missing)."""
    install_pygame()
    install_ipython()
    install_matplotlib()
    install_wandb()
    install_numpy_bool8()
