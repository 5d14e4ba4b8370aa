//! Graph variables that change while a session runs: a `[vars]` entry
//! written as the whole value (`"$scene"`) of live parameters of several
//! nodes changes all of them at the same tick (`scene=4B0H` on the console
//! switches `mesh.gradient` and `mesh.edges` together).

use crate::check::Checked;

/// A graph variable and the live parameters it sets.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LiveVar {
    /// The variable's name (as in `[vars]`, without the `$`).
    pub name: String,
    /// `(node, parameter)` pairs whose value is `"$name"`, in file order;
    /// only nodes of the plan (not pruned) and parameters declared live.
    pub uses: Vec<(String, &'static str)>,
}

/// Every variable of the graph that sets at least one live parameter of a
/// node in the plan. Variables only spliced into text (`${name}`) or bound
/// to parameters that cannot change live are left out: changing them needs
/// a new plan.
pub fn live_vars(checked: &Checked) -> Vec<LiveVar> {
    let mut out: Vec<LiveVar> = Vec::new();
    for var in &checked.graph.vars {
        let mut uses = Vec::new();
        for decl in &checked.graph.nodes {
            let Some(node) = checked.nodes.iter().find(|n| n.name == decl.name) else { continue };
            if checked.pruned.iter().any(|p| p.node == decl.name) {
                continue;
            }
            for p in &decl.params {
                if p.value.var_ref() != Some(var.name.as_str()) {
                    continue;
                }
                if let Some(spec) = node.spec.param(&p.name).filter(|s| s.live) {
                    uses.push((decl.name.clone(), spec.name));
                }
            }
        }
        if !uses.is_empty() {
            out.push(LiveVar { name: var.name.clone(), uses });
        }
    }
    out
}
