//! Nothing here: the tests are the user's code.
