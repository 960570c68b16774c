//! One integration-test binary, a module per topic.

mod aa;
mod agreement;
mod conformance;
mod counters;
mod effects;
mod golden;
mod gpu_compute;
mod hard_cases;
mod loaders;
mod oracles;
mod overlays;
mod tie_rules;
mod viewports;
mod watertight;
