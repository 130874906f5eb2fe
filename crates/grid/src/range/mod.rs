//! Bodies from front and back range images (thesis §4.6.2, §4.7.2; `method.md` §4).
