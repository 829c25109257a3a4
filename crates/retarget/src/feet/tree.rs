//! The body tree's one query the feet need.

#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
// Indexing: body ids and their parents come from the model.
#![allow(clippy::indexing_slicing)]

use mjcf::Model;

/// Whether `body` is `ancestor` or one of the bodies below it.
pub(crate) fn is_descendant(model: &Model, mut body: usize, ancestor: usize) -> bool {
    loop {
        if body == ancestor {
            return true;
        }
        if body == 0 {
            return false;
        }
        body = model.bodies[body].parent;
    }
}
