// placeholder so the hal library has a translation unit until its first source lands
