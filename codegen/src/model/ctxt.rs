//! The error collector of the model stage (serde_derive's `Ctxt`): errors
//! do not stop the stage; each is recorded with the span of the offending
//! tokens, so one compilation reports every mistake of the input at once.

use proc_macro2::Span;
use quote::ToTokens;
use std::fmt::Display;

/// Errors collected during a stage, reported together by [`Errors::finish`].
/// Dropping it unfinished is a bug of the macro (errors would be lost), and
/// panics in debug builds to say so.
#[derive(Default)]
pub struct Errors {
    errors: Vec<syn::Error>,
    /// The errors of the rules checked after lowering, each with the
    /// [`Slot`] it belongs in.
    checked: Vec<(Slot, syn::Error)>,
    finished: bool,
}

/// A place among the errors, taken while a part of the input is lowered,
/// where the rules checked on it afterwards (`super::check::check`) put
/// theirs: so that the errors are reported in the order of the input, as
/// one reads it, although the rules run after all lowering.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord)]
pub struct Slot(usize);

impl Errors {
    /// An empty collector.
    pub fn new() -> Errors {
        Errors::default()
    }

    /// Records an error spanning `tokens`.
    pub fn spanned(&mut self, tokens: impl ToTokens, message: impl Display) {
        self.errors.push(syn::Error::new_spanned(tokens, message));
    }

    /// Records an error at `span`.
    pub fn at(&mut self, span: Span, message: impl Display) {
        self.errors.push(syn::Error::new(span, message));
    }

    /// Records an error built elsewhere.
    pub fn push(&mut self, error: syn::Error) {
        self.errors.push(error);
    }

    /// The place after the errors recorded so far.
    pub fn slot(&self) -> Slot {
        Slot(self.errors.len())
    }

    /// Runs `rules` on a collector of their own and puts what they record
    /// at `slot`.
    pub fn fill(&mut self, slot: Slot, rules: impl FnOnce(&mut Errors)) {
        let mut own = Errors::new();
        rules(&mut own);
        own.finished = true;
        let errors = std::mem::take(&mut own.errors).into_iter();
        self.checked.extend(errors.map(|e| (slot, e)));
    }

    /// How many errors have been recorded; checks that build on lowered
    /// expressions compare it before and after, to skip follow-on errors
    /// caused by a placeholder.
    pub fn count(&self) -> usize {
        self.errors.len() + self.checked.len()
    }

    /// `Ok` when nothing was recorded, else all errors combined into one.
    pub fn finish(mut self) -> syn::Result<()> {
        self.finished = true;
        let mut errors = self.in_order().into_iter();
        match errors.next() {
            None => Ok(()),
            Some(mut first) => {
                first.extend(errors);
                Err(first)
            }
        }
    }
}

impl Errors {
    /// Every error, each checked one at its slot (after the errors recorded
    /// before the slot was taken, in the order the rules recorded them).
    fn in_order(&mut self) -> Vec<syn::Error> {
        let mut checked = std::mem::take(&mut self.checked);
        checked.sort_by_key(|&(slot, _)| slot);
        let mut checked = checked.into_iter().peekable();
        let mut out = Vec::new();
        for (i, error) in std::mem::take(&mut self.errors).into_iter().enumerate() {
            while let Some((_, e)) = checked.next_if(|&(slot, _)| slot <= Slot(i)) {
                out.push(e);
            }
            out.push(error);
        }
        out.extend(checked.map(|(_, e)| e));
        out
    }
}

impl Drop for Errors {
    fn drop(&mut self) {
        debug_assert!(
            self.finished || self.count() == 0 || std::thread::panicking(),
            "model errors dropped without being reported"
        );
    }
}
