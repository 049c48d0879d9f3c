int main_placeholder_1550;
