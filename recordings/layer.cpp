// placeholder so the recordings library has a translation unit until its first source lands
