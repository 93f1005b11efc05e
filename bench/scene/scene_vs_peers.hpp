#pragma once
// tightbvh-bench --scene (scene_vs_peers.cpp): whole scenes, tightbvh against FCL's manager and
// Bullet's world; tightbvh-bench's main hands its arguments over when they hold --scene.

namespace tightbvh::bench {

// The scene comparison's command line (--scene FILE [--json OUT] [--reps N] ...): exit status 0,
// 1 when tightbvh's pairs differ from brute force, 2 on bad input.
int run_scene_bench(int argc, char** argv);

}  // namespace tightbvh::bench
