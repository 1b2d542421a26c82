"""A policy as an ONNX file the Rust controller node `testbed-policy` runs
(crate `policy/`): the network, and the environment it was trained in as
the model's metadata (`metadata_props["testbed.env"]`, the JSON of the
policy's `env` dict, as `testbed.policy.env_record` writes it).

Needs only the `onnx` package (`pip install onnx`), not torch:

    from testbed.onnx_export import save_linear
    save_linear(policy, "runs/policy.onnx")        # or policy.save_onnx(...)

A `LinearPolicy` becomes MatMul and Add (obs · Wᵀ + b) then Clip(−1, 1), in float64
as numpy computes it, on an input `obs` of shape [1, obs_dim] and an output
`action` of shape [1, dof]. `python/examples/export_sb3_onnx.py` exports an
SB3 policy with the same metadata.
"""

from __future__ import annotations

import json

import numpy as np

#: The metadata key the Rust node reads the environment record from.
ENV_KEY = "testbed.env"
#: The operator set written: tract is tested on 9 to 18.
OPSET = 17


def set_env_record(model, env: dict) -> None:
    """Writes `env` (a policy's environment record) into `model`'s metadata."""
    import onnx.helper

    onnx.helper.set_model_props(model, {ENV_KEY: json.dumps(env)})


def linear_model(policy):
    """The ONNX model of `policy` (a `LinearPolicy`), checked by onnx."""
    import onnx
    from onnx import TensorProto, helper, numpy_helper

    policy.check()
    w = np.asarray(policy.weights, dtype=np.float64)
    b = np.asarray(policy.bias, dtype=np.float64)
    dof, obs_dim = w.shape
    graph = helper.make_graph(
        [
            # MatMul then Add rather than Gemm: tract's Gemm makes its alpha
            # and beta f32 and fails on a float64 model.
            helper.make_node("MatMul", ["obs", "Wt"], ["wx"]),
            helper.make_node("Add", ["wx", "b"], ["raw"]),
            helper.make_node("Clip", ["raw", "lo", "hi"], ["action"]),
        ],
        "testbed_linear_policy",
        [helper.make_tensor_value_info("obs", TensorProto.DOUBLE, [1, obs_dim])],
        [helper.make_tensor_value_info("action", TensorProto.DOUBLE, [1, dof])],
        initializer=[
            numpy_helper.from_array(np.ascontiguousarray(w.T), "Wt"),
            numpy_helper.from_array(b, "b"),
            numpy_helper.from_array(np.array(-1.0), "lo"),
            numpy_helper.from_array(np.array(1.0), "hi"),
        ],
    )
    model = helper.make_model(graph, producer_name="testbed.onnx_export",
                              opset_imports=[helper.make_opsetid("", OPSET)])
    # The IR version onnx's own checker and older readers accept.
    model.ir_version = 8
    set_env_record(model, policy.env)
    onnx.checker.check_model(model)
    return model


def save_linear(policy, path) -> None:
    """Writes `policy` (a `LinearPolicy`) as an ONNX file at `path`."""
    import onnx

    onnx.save(linear_model(policy), str(path))
