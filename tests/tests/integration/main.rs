//! One integration-test binary, a module per topic.

mod agreement;
mod loaders;
mod tie_rules;
mod watertight;
