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
    finished: bool,
}

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

    /// How many errors have been recorded; checks that build on lowered
    /// expressions compare it before and after, to skip follow-on errors
    /// caused by a placeholder.
    pub fn count(&self) -> usize {
        self.errors.len()
    }

    /// `Ok` when nothing was recorded, else all errors combined into one.
    pub fn finish(mut self) -> syn::Result<()> {
        self.finished = true;
        let mut errors = std::mem::take(&mut self.errors).into_iter();
        match errors.next() {
            None => Ok(()),
            Some(mut first) => {
                first.extend(errors);
                Err(first)
            }
        }
    }
}

impl Drop for Errors {
    fn drop(&mut self) {
        debug_assert!(
            self.finished || self.errors.is_empty() || std::thread::panicking(),
            "model errors dropped without being reported"
        );
    }
}
