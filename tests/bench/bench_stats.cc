int main_placeholder_20578;
