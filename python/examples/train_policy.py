"""Train a linear policy on testbed/ArmTracking-v0 by random search (no
dependencies beyond the module) and save it for `testbed.policy_node`.

    python python/examples/train_policy.py --out runs/policy.npz
    testbed compare --duration 4 --controller-cmd policy="python -m testbed.policy_node --policy runs/policy.npz"

By default the policy is a residual on `pd` over the paper's scenario, with
the environment's defaults: episodes of 4 s (T_c = 2 s and as long again to
settle; run it for as long as it was trained: --duration 4), decisions at
50 Hz. --base-law none learns the torques themselves.
"""

import argparse

import gymnasium

import testbed
from testbed.policy import LinearPolicy, env_record, episode_return, random_search


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--scenario", default="paper")
    p.add_argument("--robot", default=None)
    p.add_argument("--episode-s", type=float, default=4.0,
                   help="episode length, s (run the policy as long: --duration)")
    p.add_argument("--base-law", default="pd", help="a built-in law, or 'none'")
    p.add_argument("--iterations", type=int, default=10)
    p.add_argument("--directions", type=int, default=8)
    p.add_argument("--seed", type=int, default=0, help="the episode's seed (its scenario draw)")
    p.add_argument("--out", required=True, help="the policy file to write (.npz)")
    a = p.parse_args()
    kwargs = {"scenario": a.scenario, "robot": a.robot, "episode_s": a.episode_s,
              "base_law": None if a.base_law == "none" else a.base_law}
    env = gymnasium.make(testbed.ENV_ID, **kwargs)
    core = env.unwrapped.core
    record = {**kwargs, **env_record(env)}
    if a.scenario not in testbed.SCENARIOS:
        # A policy file names only shipped scenarios: one of your own goes
        # in with it (it must name no file: pass the robot as --robot).
        with open(a.scenario, encoding="utf-8") as f:
            record["scenario_toml"] = f.read()
        del record["scenario"]
    policy = LinearPolicy.zeros(core.dof, core.obs_dim, record)
    print(f"return of the zero policy: {episode_return(env, policy, a.seed):.2f}")
    policy = random_search(env, policy, iterations=a.iterations, directions=a.directions,
                           top=max(1, a.directions // 2), episode_seed=a.seed,
                           callback=lambda it, r: print(f"iteration {it + 1}: return {r:.2f}"))
    policy.save(a.out)
    print(f"wrote {a.out}; run it as trained: --duration {a.episode_s:g}")


if __name__ == "__main__":
    main()
