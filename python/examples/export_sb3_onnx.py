"""Exports a Stable-Baselines3 PPO policy (its deterministic action: the
mean of the Gaussian, clipped to the action space) to ONNX with the
environment record the Rust node `testbed-policy` reads, so that the
policy runs in `testbed run` and `testbed compare` with no Python in the
loop:

    python python/examples/train_sb3.py --out runs/ppo_arm          # trains, saves runs/ppo_arm.zip
    python python/examples/export_sb3_onnx.py runs/ppo_arm.zip runs/ppo_arm.onnx
    cargo run --release -- compare --scenario paper_randomised --set controller.k1=3.75 \\
        --set controller.k2=3.75 --laws nac,pd --controller-cmd ppo="target/release/testbed-policy runs/ppo_arm.onnx"

Needs torch (with Stable-Baselines3) and onnx; the tests do not run it.
The environment is rebuilt with the settings train_sb3.py saved beside
the model (MODEL.env.json; `--defaults`: train_sb3.py's KWARGS, for a
model from before that file) to read its record (`testbed.policy.env_record`).
"""

import argparse
import json
import sys
from pathlib import Path

import gymnasium
import numpy as np

import testbed
from testbed.onnx_export import set_env_record
from testbed.policy import env_record

sys.path.insert(0, str(Path(__file__).parent))
from train_sb3 import KWARGS  # noqa: E402  (the settings it was trained with)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("model", help="the SB3 PPO file (.zip)")
    p.add_argument("out", help="the ONNX file to write")
    p.add_argument("--defaults", action="store_true",
                   help="no MODEL.env.json: the model was trained with train_sb3.py's KWARGS "
                        "(a policy from before the file was written)")
    a = p.parse_args()

    import onnx
    import torch
    from stable_baselines3 import PPO

    saved = Path(a.model.removesuffix(".zip") + ".env.json")
    if saved.exists():
        kwargs = json.loads(saved.read_text())
    elif a.defaults:
        kwargs = KWARGS
    else:
        sys.exit(f"export_sb3_onnx: {saved} is missing (train_sb3.py writes it beside the model); "
                 "--defaults exports with train_sb3.py's KWARGS, for a model trained without options")
    model = PPO.load(a.model, device="cpu")
    policy = model.policy

    class Mean(torch.nn.Module):
        """obs → clip(mean action, -1, 1): what predict(deterministic=True) returns."""

        def __init__(self, policy):
            super().__init__()
            self.policy = policy

        def forward(self, obs):
            features = self.policy.extract_features(obs, self.policy.pi_features_extractor)
            latent = self.policy.mlp_extractor.forward_actor(features)
            return torch.clamp(self.policy.action_net(latent), -1.0, 1.0)

    env = gymnasium.make(testbed.ENV_ID, **kwargs)
    core = env.unwrapped.core
    record = dict(kwargs, **env_record(env))
    record["set"] = [f"{k}={v}" for k, v in kwargs.get("set", {}).items()]
    obs = torch.zeros((1, core.obs_dim), dtype=torch.float32)
    # The TorchScript exporter (dynamo=False) needs no onnxscript.
    torch.onnx.export(Mean(policy).eval(), (obs,), a.out, input_names=["obs"],
                      output_names=["action"], opset_version=17, dynamo=False)
    onnx_model = onnx.load(a.out)
    set_env_record(onnx_model, record)
    onnx.checker.check_model(onnx_model)
    onnx.save(onnx_model, a.out)

    # The exported network against SB3's own deterministic action.
    o, _ = env.reset(seed=0)
    want, _ = model.predict(o, deterministic=True)
    with torch.no_grad():
        got = Mean(policy)(torch.as_tensor(o, dtype=torch.float32)[None]).numpy()[0]
    print(f"wrote {a.out}: max |torch - predict| = {np.max(np.abs(got - want)):.2e} on one observation")


if __name__ == "__main__":
    main()
