#!/usr/bin/env python3
"""Convert a reference-code policy (a whole `DDRQN` module saved with `torch.save`) into a plain
state_dict safetensors file that `macdec import` reads.

    pip install torch safetensors numpy
    python scripts/torch_to_safetensors.py agent_010.pt a0.safetensors

Optional tool: macdec's tests and CI never need it or torch.

Why not `torch.load(path).state_dict()`: the reference's files are torch 1.1-era pickles of whole
modules. Unpickling them runs each module's `__setstate__`, which in current torch fails for
`nn.LSTM` (no `_flat_weights`), and needs the reference's own `rlmamr` package importable. This
script instead maps every module class (torch.nn's and the reference's `DDRQN`) to a plain
record that only keeps the pickled attributes, lets torch rebuild just the tensors
(`torch._utils._rebuild_tensor_v2`, storages), and collects the `_parameters` of the module tree
under their dotted names: `fc1.weight`, ..., `lstm.weight_ih_l0` (MacDec-MADDRQN's
`MA_dec_cen_hddrqn`) or `rnn.weight_ih_l0` (Dec-HDDRQN's `MA_hddrqn`). Names are kept as found;
`macdec import` accepts both schemes. Anything else in the pickle that is not a tensor, a storage
or a plain container is also replaced by a record, so no code from the file runs.

A file that already holds a state_dict (`torch.save(net.state_dict())`) converts too, and with
`--key K` the state_dict stored under K of a saved dict: ACAC's actor checkpoints
(`<run_id>_agent_<i>_1.tar`) hold it under `actor_net_state_dict`:

    python scripts/torch_to_safetensors.py --key actor_net_state_dict 0_agent_0_1.tar a0.safetensors
"""

import argparse
import collections
import pickle
import sys
import types
import warnings

# Callables the pickle may use for real: tensor and parameter rebuilding and ordered dicts.
# Everything else becomes a `Record` (storages are resolved by torch's own unpickler first).
ALLOWED = {
    ("collections", "OrderedDict"),
    ("torch._utils", "_rebuild_tensor_v2"),
    ("torch._utils", "_rebuild_tensor"),
    ("torch._utils", "_rebuild_parameter"),
    ("torch._utils", "_rebuild_parameter_with_state"),
    ("torch", "Size"),
    ("torch", "device"),
    ("torch", "float32"),
}

DDRQN_TENSORS = ["fc1.weight", "fc1.bias", "fc2.weight", "fc2.bias",
                 "weight_ih_l0", "weight_hh_l0", "bias_ih_l0", "bias_hh_l0",
                 "fc3.weight", "fc3.bias", "fc4.weight", "fc4.bias"]


class Record:
    """Stand-in for a pickled class: keeps constructor arguments and state, runs nothing."""

    qualname = "?"

    def __init__(self, *args, **kwargs):
        self._args, self._kwargs = args, kwargs

    def __setstate__(self, state):
        # Modules pickle their __dict__; some objects pickle (dict, slots).
        if isinstance(state, tuple) and len(state) == 2 and isinstance(state[0], (dict, type(None))):
            state = dict(state[0] or {}, **(state[1] or {}))
        if isinstance(state, dict):
            self.__dict__.update(state)
        else:
            self._state = state


def record_class(module, name):
    """A distinct Record subclass per pickled class, named after it (for error messages)."""
    return type(name, (Record,), {"qualname": f"{module}.{name}"})


class SafeUnpickler(pickle.Unpickler):
    def find_class(self, module, name):
        if (module, name) in ALLOWED:
            return super().find_class(module, name)
        return record_class(module, name)


# torch.load takes a "pickle module": this one is the standard module with our Unpickler.
safe_pickle = types.ModuleType("safe_pickle")
safe_pickle.__dict__.update({k: getattr(pickle, k) for k in dir(pickle) if not k.startswith("__")})
safe_pickle.Unpickler = SafeUnpickler


def collect_parameters(obj, prefix=""):
    """Dotted name -> tensor for every parameter in a pickled module tree (state_dict order)."""
    import torch

    out = collections.OrderedDict()
    params = getattr(obj, "_parameters", None) or {}
    for name, tensor in params.items():
        if tensor is not None:
            out[prefix + name] = tensor
    modules = getattr(obj, "_modules", None) or {}
    for name, child in modules.items():
        if child is not None:
            out.update(collect_parameters(child, prefix + name + "."))
    if not out and isinstance(obj, dict) and all(isinstance(v, torch.Tensor) for v in obj.values()):
        out.update((prefix + k, v) for k, v in obj.items())  # already a state_dict
    return out


def convert(src, dst, key=None):
    import numpy as np
    import torch
    from safetensors.numpy import save_file

    with warnings.catch_warnings():
        # Source-change warnings: the Records are not the classes the file was saved with.
        warnings.simplefilter("ignore")
        root = torch.load(src, map_location="cpu", pickle_module=safe_pickle, weights_only=False)
    if key is not None:
        if not isinstance(root, dict) or key not in root:
            found = sorted(root) if isinstance(root, dict) else type(root).__name__
            sys.exit(f"{src}: no entry `{key}` (found {found})")
        root = root[key]
    params = collect_parameters(root)
    if not params:
        kind = getattr(type(root), "qualname", type(root).__name__)
        sys.exit(f"{src}: no parameters found in the pickled {kind}")
    arrays = collections.OrderedDict()
    for name, tensor in params.items():
        arrays[name] = np.ascontiguousarray(tensor.detach().to(torch.float32).cpu().numpy())
    rnns = sorted({n.split(".")[0] for n in arrays if n.split(".")[-1] in DDRQN_TENSORS[4:8]})
    kind = getattr(type(root), "qualname", type(root).__name__)
    save_file(arrays, dst, metadata={"format": "pt", "source": str(src), "module": kind})
    print(f"{src}: {kind} -> {dst}: {len(arrays)} tensors (recurrent layer `{'/'.join(rnns) or '-'}`)")
    for name, a in arrays.items():
        print(f"  {name} {list(a.shape)}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("src", help="a torch.save'd DDRQN module (.pt) or state_dict")
    parser.add_argument("dst", help="the safetensors file to write")
    parser.add_argument("--key", help="take the state_dict stored under this key of a saved dict "
                        "(ACAC's actor checkpoints: actor_net_state_dict)")
    args = parser.parse_args()
    convert(args.src, args.dst, args.key)


if __name__ == "__main__":
    main()
