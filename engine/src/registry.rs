//! The set of node types a loader knows.

use crate::spec::NodeSpec;

/// Node types by name. The node library provides the full registry; tests
/// may build smaller ones.
#[derive(Debug, Clone, Default)]
pub struct Registry {
    specs: Vec<&'static NodeSpec>,
    /// Node types this build left out, with the cargo feature that has them.
    absent: Vec<(&'static str, &'static str)>,
}

impl Registry {
    /// An empty registry.
    pub fn new() -> Self {
        Self::default()
    }
    /// Adds a node type. Panics on a duplicate name — a programming error in
    /// the node library, caught by its tests.
    pub fn add(&mut self, spec: &'static NodeSpec) -> &mut Self {
        assert!(self.get(spec.name).is_none(), "node type `{}` registered twice", spec.name);
        self.specs.push(spec);
        self
    }
    /// The node type of that name.
    pub fn get(&self, name: &str) -> Option<&'static NodeSpec> {
        self.specs.iter().copied().find(|s| s.name == name)
    }
    /// All node types, in registration order.
    pub fn specs(&self) -> impl Iterator<Item = &'static NodeSpec> + Clone + '_ {
        self.specs.iter().copied()
    }
    /// Records that node type `name` exists but this build left it out;
    /// `feature` is the cargo feature that brings it in.
    pub fn add_absent(&mut self, name: &'static str, feature: &'static str) -> &mut Self {
        self.absent.push((name, feature));
        self
    }
    /// The cargo feature that would bring in node type `name`, when this
    /// build left it out.
    pub fn absent(&self, name: &str) -> Option<&'static str> {
        self.absent.iter().find(|(n, _)| *n == name).map(|(_, f)| *f)
    }
    /// The safety guards (specs with `safety_guard`, the only nodes that may
    /// feed hardware) as messages name them: "`limit`", "`a` or `b`", or
    /// "safety-guard" when the registry has none.
    pub fn guard_words(&self) -> String {
        let names: Vec<String> = self.specs().filter(|s| s.is_guard()).map(|s| format!("`{}`", s.name)).collect();
        if names.is_empty() {
            "safety-guard".to_string()
        } else {
            names.join(" or ")
        }
    }
    /// All type names.
    pub fn names(&self) -> impl Iterator<Item = &'static str> + Clone + '_ {
        self.specs.iter().map(|s| s.name)
    }
}
